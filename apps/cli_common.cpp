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
  cmd.add_flag("--quiet,-q", opt.quiet, "do not print the resolved scene");
}

Scene resolve_scene(const SceneOptions& opt) {
  Scene scene = opt.scene_file.empty() ? Scene{} : load_scene_file(opt.scene_file);
  if (opt.beta) set_parameter(scene, "joint_set.dip_deg", fmt::format("{:.17g}", *opt.beta));
  if (opt.spacing) set_parameter(scene, "joint_set.spacing", fmt::format("{:.17g}", *opt.spacing));
  if (!opt.mesh_file.empty()) scene.mesh.file = opt.mesh_file;
  for (const auto& s : opt.sets) apply_override(scene, s);
  validate(scene);
  return scene;
}

void print_scene(const Scene& scene, const SceneOptions& opt) {
  if (opt.quiet) return;
  fmt::print("# resolved scene{}\n{}\n", opt.scene_file.empty() ? " (built-in defaults)" : " from " + opt.scene_file,
             to_toml(scene));
}

}  // namespace rbdem::cli
