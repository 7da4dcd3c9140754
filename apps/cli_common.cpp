// Shared command-line options, checks and the cost estimate. See cli_common.hpp.
#include "apps/cli_common.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <set>
#include <thread>

#include <fmt/format.h>

namespace rbdem::cli {

void add_scene_options(CLI::App& cmd, SceneOptions& opt) {
  cmd.add_option("scene", opt.scene_file, fmt::format("scene file (TOML); default: {}", builtin_scene));
  cmd.add_option("--scene", opt.scene_option, "scene file (TOML), instead of the positional argument");
  cmd.add_option("--set", opt.sets, "override one scene key, e.g. --set rock.cohesion=20e6 (SI units; repeatable)")
      ->type_name("KEY=VALUE")
      ->allow_extra_args(false);
  cmd.add_option("--beta", opt.beta, "joint dip from the horizontal [deg] (joint_set.dip_deg, 0..90)");
  cmd.add_option("--spacing", opt.spacing, "joint spacing [m] (joint_set.spacing)");
  cmd.add_option("--mesh", opt.mesh_file,
                 "use this gmsh .msh file (physical surfaces = layers) instead of meshing; it fixes the geometry, so "
                 "--beta, --spacing and --set of specimen sizes, joint_set.* or mesh.size are refused with it");
  add_force_flag(cmd, opt.force);
  cmd.add_flag("--quiet,-q", opt.quiet, "do not print the resolved scene, the cost estimate or progress");
}

void add_force_flag(CLI::App& cmd, bool& force) {
  cmd.add_flag("--force", force,
               "run a scene that looks like a mistake: a bond strength at or above its modulus (a unit mistake), "
               "or an estimated memory above what the machine has available");
}

std::string scene_path(const SceneOptions& opt) {
  if (!opt.scene_file.empty() && !opt.scene_option.empty())
    throw std::invalid_argument(fmt::format("give the scene once: '{}' as the argument and '{}' with --scene; keep "
                                            "one of them",
                                            opt.scene_file, opt.scene_option));
  return opt.scene_file.empty() ? opt.scene_option : opt.scene_file;
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

// The keys a user mesh fixes: its nodes give the specimen's size and shape, its physical surfaces the layers, its
// triangles the mesh size. specimen.thickness (the bond area), specimen.model (the continuum's plane strain or
// stress) and specimen.shape (which test and gauges apply) still act with a mesh file, so they stay settable.
bool fixed_by_mesh(std::string_view key) {
  return key == "mesh.size" || key.starts_with("joint_set.") || key == "specimen.width" || key == "specimen.height" ||
         key == "specimen.diameter" || key == "specimen.contact_arc_deg";
}

// With a user mesh, refuses the options that would be silently ignored.
void refuse_options_a_mesh_overrides(const SceneOptions& opt, const Scene& scene) {
  if (scene.mesh.file.empty()) return;
  const std::string source = !opt.mesh_file.empty() ? fmt::format("--mesh {}", opt.mesh_file)
                                                    : fmt::format("the mesh file {} (mesh.file)", scene.mesh.file);
  auto refuse = [&](const std::string& option, std::string_view key) {
    throw std::invalid_argument(fmt::format(
        "{} cannot be used with {}: the mesh file fixes the specimen's geometry and layers, so {} would be ignored. "
        "Make a mesh with it (rbdem mesh {} --out FILE.msh) and pass that file, or leave out the mesh file",
        option, source, key, option));
  };
  if (opt.beta) refuse(fmt::format("--beta {:g}", *opt.beta), "joint_set.dip_deg");
  if (opt.spacing) refuse(fmt::format("--spacing {:g}", *opt.spacing), "joint_set.spacing");
  for (const auto& s : opt.sets) {
    std::string key = s.substr(0, s.find('='));
    key.erase(0, key.find_first_not_of(" \t"));
    key.erase(key.find_last_not_of(" \t") + 1);
    if (fixed_by_mesh(key)) refuse("--set " + s, key);
  }
}

}  // namespace

Scene resolve_scene(const SceneOptions& opt) {
  const std::string file = scene_path(opt);
  Scene scene = file.empty() ? Scene{} : load_input(file, InputKind::scene, load_scene_file);
  if (opt.beta) set_shorthand(scene, "--beta", "joint_set.dip_deg", *opt.beta);
  if (opt.spacing) set_shorthand(scene, "--spacing", "joint_set.spacing", *opt.spacing);
  if (!opt.mesh_file.empty()) scene.mesh.file = opt.mesh_file;
  for (const auto& s : opt.sets) apply_override(scene, s);
  refuse_options_a_mesh_overrides(opt, scene);
  validate(scene);
  if (!opt.force) check_plausible(scene);
  return scene;
}

void print_scene(const Scene& scene, const SceneOptions& opt) {
  if (opt.quiet) return;
  const std::string file = scene_path(opt);
  fmt::print("# resolved scene from {}\n{}\n", file.empty() ? std::string(builtin_scene) : file, to_toml(scene));
}

// --- what a file holds ---------------------------------------------------------------------------------------

InputKind input_kind(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) return InputKind::unknown;
  std::set<std::string> sections;
  for (const auto& p : scene_parameters()) sections.insert(p.key.substr(0, p.key.find('.')));
  bool any = false, all_scene = true;
  for (std::string line; std::getline(in, line);) {
    const auto at = line.find_first_not_of(" \t");
    if (at == std::string::npos || line[at] != '[') continue;
    // "[study]", "[[axis]]", "[study.set]", "[ rock ]": the first name of the header
    const auto begin = line.find_first_not_of("[ \t\"", at);
    if (begin == std::string::npos) continue;
    const std::string name = line.substr(begin, line.find_first_of(".]\" \t", begin) - begin);
    if (name == "study" || name == "axis") return InputKind::study;
    if (name == "calibrate" || name == "parameter" || name == "target") return InputKind::calibration;
    any = true;
    all_scene = all_scene && sections.count(name) > 0;
  }
  return any && all_scene ? InputKind::scene : InputKind::unknown;
}

void refuse_wrong_input(const std::filesystem::path& file, InputKind expected) {
  const InputKind kind = input_kind(file);
  if (kind == InputKind::unknown || kind == expected) return;
  const std::string f = file.string();
  const char* wanted = expected == InputKind::scene ? "a scene" : expected == InputKind::study ? "a study"
                                                                                                 : "calibration targets";
  switch (kind) {
    case InputKind::study:
      throw SceneError(fmt::format("{0} is a study file (it has a [study] table), not {1}: run the study with "
                                   "`rbdem sweep {0}`",
                                   f, wanted));
    case InputKind::calibration:
      throw SceneError(fmt::format("{0} is a calibration file (it has a [calibrate] table), not {1}: run it with "
                                   "`rbdem calibrate {0}`",
                                   f, wanted));
    default:
      throw SceneError(fmt::format("{0} is a scene file (it has neither a [study] nor a [calibrate] table), not {1}: "
                                   "run one test of it with `rbdem ucs {0}`, or name it as the base scene of a study "
                                   "(scenes/study_*.toml) or a calibration (scenes/calibrate_paper.toml)",
                                   f, wanted));
  }
}

std::string closest(std::string_view word, const std::vector<std::string>& candidates, std::size_t max_distance) {
  // Levenshtein distance, one row at a time.
  auto distance = [](std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      std::size_t diagonal = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const std::size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
        diagonal = up;
      }
    }
    return row[b.size()];
  };
  std::string best;
  std::size_t best_distance = max_distance + 1;
  for (const auto& c : candidates)
    if (const std::size_t d = distance(word, c); d < best_distance) best = c, best_distance = d;
  return best;
}

// --- the cost estimate ---------------------------------------------------------------------------------------
//
// Measured on the paper scene (100 x 50 mm, joints every 10 mm) with this build on a shared 2-core machine (other
// jobs ran alongside, so the times are good to about +-30 %):
//   blocks      rbdem mesh: 3462 at mesh.size 2 mm, 13418 at 1 mm, 52422 at 0.5 mm, i.e. 2.77, 2.68, 2.62 x
//               area / mesh.size^2 (the 50 mm disc at 1 mm: 5140 blocks, 2.62 x); bonds 1.48 to 1.49 x blocks.
//   memory      peak resident set of rbdem ucs --beta 30 (/usr/bin/time -v): 185 MB at 3472 blocks (2 mm),
//               232 MB at 13202 (1 mm), 439 MB at 52890 (0.5 mm): 4.8 kB per block from 2 to 1 mm, 5.2 kB from 1
//               to 0.5 mm (the static start's sparse factor grows a little faster than the blocks), over a fixed
//               160 MB (rbdem --version alone peaks at 158 MB: the libraries).
//   time step   the critical step is 0.19 to 0.22 x mesh.size x sqrt(density / E*) (summary.json dt_critical_s at
//               0.5, 1 and 2 mm); the run takes numerics.dt_safety of it.
//   steps       from the static elastic start the explicit run to the post-peak stop covered 3.5e-5 to 4.9e-5 axial
//               strain (1 and 0.5 mm): about the rock bonds' failure strain max(sigma_c, c) / E* = 4.7e-5. Without
//               the elastic start it covers the rise to the peak too: 2.0e-4 to 2.3e-4 at 2 mm, 4.5 x that strain.
//   per step    wall / (steps x blocks) of whole runs on one thread (meshing, static start and writing included):
//               41 to 43 ns at 1 mm (beta 30, 90), 59 ns at beta 0, 93 ns at 0.5 mm with a load average of 5; 50 ns
//               is taken. Two threads run 1.9 x faster on an idle machine (docs/performance.md, BM_EngineStep); on
//               this busy one they ran 5 x slower, so the time assumes idle cores.
namespace {

constexpr double blocks_per_area = 2.7;       // blocks per (area / mesh.size^2)
constexpr double bonds_per_block = 1.5;
constexpr double fixed_bytes = 160e6;         // the process before any block
constexpr double bytes_per_block = 5.2e3;
constexpr double critical_step_factor = 0.19; // dt_critical / (mesh.size sqrt(density / E*))
constexpr double seconds_per_block_step = 50e-9;
constexpr double strain_from_elastic_start = 1.0, strain_from_rest = 4.5;  // x the rock bonds' failure strain
constexpr double thread_efficiency = 0.95;

double specimen_area(const Scene& s) {
  return s.specimen.shape == "disc" ? std::numbers::pi / 4 * s.specimen.diameter * s.specimen.diameter
                                    : s.specimen.width * s.specimen.height;
}

// MemAvailable from /proc/meminfo, in bytes; 0 when it cannot be read.
double available_memory() {
  std::ifstream in("/proc/meminfo");
  std::string name;
  double kb = 0;
  std::string unit;
  while (in >> name >> kb >> unit)
    if (name == "MemAvailable:") return kb * 1024.0;
  return 0.0;
}

std::string count_text(double n) {
  if (n < 1e4) return fmt::format("{:.0f}", n);
  if (n < 1e6) return fmt::format("{:.0f}k", n / 1e3);
  return fmt::format("{:.1f}M", n / 1e6);
}

std::string bytes_text(double b) { return b < 1e9 ? fmt::format("{:.0f} MB", b / 1e6) : fmt::format("{:.1f} GB", b / 1e9); }

// Rounded up to two significant digits, so the suggested size does fit.
double round_up(double x) {
  const double unit = std::pow(10.0, std::floor(std::log10(x)) - 1);
  return std::ceil(x / unit - 1e-9) * unit;
}

}  // namespace

std::string duration_text(double seconds) {
  if (!std::isfinite(seconds)) return "?";
  if (seconds < 90) return fmt::format("{:.0f} s", seconds);
  if (seconds < 90 * 60) return fmt::format("{:.0f} min", seconds / 60);
  if (seconds < 48 * 3600) return fmt::format("{:.1f} h", seconds / 3600);
  return fmt::format("{:.1f} days", seconds / 86400);
}

CostEstimate estimate_cost(const Scene& scene) {
  CostEstimate e;
  const double h = scene.mesh.size;
  e.blocks = blocks_per_area * specimen_area(scene) / (h * h);
  e.bonds = bonds_per_block * e.blocks;
  e.bytes = fixed_bytes + bytes_per_block * e.blocks;
  const Scene& s = scene;
  const double stiffest = std::max(s.rock.effective_modulus, s.joint.effective_modulus);
  const double dt = s.numerics.dt > 0 ? s.numerics.dt
                                      : s.numerics.dt_safety * critical_step_factor * h *
                                            std::sqrt(s.rock.density * s.numerics.mass_scaling / stiffest);
  const double failure_strain = std::max(s.rock.tensile_strength, s.rock.cohesion) / s.rock.effective_modulus;
  const double strain = std::min(s.loading.max_strain, (s.numerics.elastic_start ? strain_from_elastic_start : strain_from_rest) * failure_strain);
  const double length = s.specimen.shape == "disc" ? s.specimen.diameter : s.specimen.height;
  e.steps = strain * length / (s.loading.platen_velocity * dt);
  e.threads = s.numerics.threads > 0 ? s.numerics.threads : int(std::max(1u, std::thread::hardware_concurrency()));
  const double speedup = e.threads == 1 ? 1.0 : thread_efficiency * e.threads;
  e.seconds = e.steps * e.blocks * seconds_per_block_step / speedup;
  return e;
}

std::string describe(const CostEstimate& e) {
  return fmt::format("about {} blocks, {} bonds, {} of memory, {} per run on {} thread{}", count_text(e.blocks),
                     count_text(e.bonds), bytes_text(e.bytes), duration_text(e.seconds), e.threads,
                     e.threads == 1 ? "" : "s");
}

void check_cost(const Scene& scene, std::string_view who, int concurrent, bool force, bool quiet) {
  const CostEstimate e = estimate_cost(scene);
  const double need = e.bytes * std::max(concurrent, 1), available = available_memory();
  if (!force && available > 0 && need > available) {
    // The finest mesh.size whose runs fit in 80 % of the available memory.
    const double fit_blocks = (0.8 * available / std::max(concurrent, 1) - fixed_bytes) / bytes_per_block;
    const double fit_size = fit_blocks > 0 ? round_up(std::sqrt(blocks_per_area * specimen_area(scene) / fit_blocks)) : 0;
    const std::string suggestion = fit_size > 0 ? fmt::format("use mesh.size >= {0:g} m (--set mesh.size={0:g})", fit_size)
                                                : std::string("use a coarser mesh.size");
    throw SceneError(fmt::format(
        "mesh.size = {:g} m needs an estimated {} of memory (about {} blocks and {} bonds per run{}), more than the "
        "{} this machine has available (MemAvailable in /proc/meminfo): {}{}; --force runs it anyway",
        scene.mesh.size, bytes_text(need), count_text(e.blocks), count_text(e.bonds),
        concurrent > 1 ? fmt::format(", {} runs at once", concurrent) : "", bytes_text(available), suggestion,
        concurrent > 1 ? ", or run fewer cases at once (--workers)" : ""));
  }
  if (!quiet && (e.blocks > 2e5 || need > 2e9 || e.seconds > 600))
    fmt::print("{}: estimate before meshing: {} (mesh.size = {:g} m)\n", who, describe(e), scene.mesh.size);
}

}  // namespace rbdem::cli
