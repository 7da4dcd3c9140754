// Shared command-line options. See cli_common.hpp.
#include "apps/cli_common.hpp"

#include <fmt/format.h>

namespace rbdem::cli {

void add_scene_options(CLI::App& cmd, SceneOptions& opt) {
  cmd.add_option("scene", opt.scene_file, "scene file (TOML); default: the built-in paper scene (scenes/paper.toml)");
  cmd.add_option("--scene", opt.scene_file, "scene file (TOML), same as the positional argument");
  cmd.add_option("--set", opt.sets, "override one scene key, e.g. --set rock.cohesion=20e6 (SI units; repeatable)")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  cmd.add_option("--beta", opt.beta, "joint dip from the horizontal [deg] (joint_set.dip_deg, 0..90)");
  cmd.add_option("--spacing", opt.spacing, "joint spacing [m] (joint_set.spacing)");
  cmd.add_option("--mesh", opt.mesh_file, "use this gmsh .msh file (physical surfaces = layers) instead of meshing");
  add_force_flag(cmd, opt.force);
  cmd.add_flag("--quiet,-q", opt.quiet, "do not print the resolved scene");
}

void add_force_flag(CLI::App& cmd, bool& force) {
  cmd.add_flag("--force", force,
               "run a scene that looks like a unit mistake (a bond strength at or above its modulus)");
}

namespace {

// A shorthand option: the message names the option the user typed as well as the key it sets.
void set_shorthand(Scene& scene, std::string_view option, std::string_view key, double value) {
  try {
    set_parameter(scene, key, fmt::format("{:.17g}", value));
  } catch (const SceneError& e) {
    throw SceneError(fmt::format("{} {}: {}", option, value, e.what()));
  }
}

}  // namespace

Scene resolve_scene(const SceneOptions& opt) {
  Scene scene = opt.scene_file.empty() ? Scene{} : load_scene_file(opt.scene_file);
  if (opt.beta) set_shorthand(scene, "--beta", "joint_set.dip_deg", *opt.beta);
  if (opt.spacing) set_shorthand(scene, "--spacing", "joint_set.spacing", *opt.spacing);
  if (!opt.mesh_file.empty()) scene.mesh.file = opt.mesh_file;
  for (const auto& s : opt.sets) apply_override(scene, s);
  validate(scene);
  if (!opt.force) check_plausible(scene);
  return scene;
}

Scene gate_scene(const Scene& scene) {
  Scene s = scene;
  s.specimen.shape = "rectangle";
  s.loading.confining_pressure = 0.0;
  return s;
}

void print_scene(const Scene& scene, const SceneOptions& opt) {
  if (opt.quiet) return;
  fmt::print("# resolved scene{}\n{}\n", opt.scene_file.empty() ? " (built-in defaults)" : " from " + opt.scene_file,
             to_toml(scene));
}

}  // namespace rbdem::cli
