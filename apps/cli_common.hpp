// Options every rbdem command shares (the scene file, --set overrides, the --beta/--spacing/--mesh shorthands),
// the checks of a command line that CLI11 cannot make (a scene given twice, options a mesh file overrides, a study
// where a scene belongs), and the cost estimate of a run made before meshing.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "compare/gate/gate_cache.hpp"
#include "dem/scene.hpp"

namespace rbdem::cli {

// Exit status of every command: 0 done, 1 the run failed, 2 bad input (scene, options, files),
// 3 a physical check failed (the elastic gate).
enum Exit : int { ok = 0, run_failed = 1, bad_input = 2, check_failed = 3 };

// How help texts and the printed scene name the scene used when no file is given.
inline constexpr const char* builtin_scene = "the built-in paper scene (the same values as scenes/paper.toml)";

struct SceneOptions {
  std::string scene_file;    // the positional argument
  std::string scene_option;  // --scene (the same; giving both is refused)
  std::vector<std::string> sets;
  std::optional<double> beta, spacing;
  std::string mesh_file;
  bool quiet = false;
  bool force = false;  // skip check_plausible and the memory check (likely mistakes the user may mean)
};

// Adds [scene] positional, --scene, --set, --beta, --spacing, --mesh, --force and --quiet to a command.
void add_scene_options(CLI::App& cmd, SceneOptions& opt);
// The --force flag, shared by every command that reads a scene.
void add_force_flag(CLI::App& cmd, bool& force);
// The scene file given (the positional argument or --scene; both at once is refused), empty for the built-in one.
std::string scene_path(const SceneOptions& opt);
// Built-in defaults <- scene file <- shorthands <- --set, validated, then checked for likely unit mistakes
// unless --force. Refuses the options a user mesh overrides. Throws SceneError or std::invalid_argument.
Scene resolve_scene(const SceneOptions& opt);
// Prints the resolved scene (TOML) under a heading, unless quiet.
void print_scene(const Scene& scene, const SceneOptions& opt);
// The scene the elastic gate checks for a test (compare/gate/gate_cache.hpp; the Python module uses it too).
using compare::gate_scene;

// What a TOML file named on the command line holds, judged by its table headers ([study], [calibrate], scene
// sections), so that a study given where a scene belongs (or the converse) is refused with the command to use.
enum class InputKind { unknown, scene, study, calibration };
InputKind input_kind(const std::filesystem::path& file);
// Throws a SceneError naming the command that reads `file` when it holds another kind of input than `expected`;
// returns when it is of that kind or cannot be judged.
void refuse_wrong_input(const std::filesystem::path& file, InputKind expected);
// load(file); when that fails on a file of another kind (a study given where a scene belongs, ...), the error names
// the command that reads it instead.
template <class Load>
auto load_input(const std::filesystem::path& file, InputKind expected, Load load) {
  try {
    return load(file);
  } catch (const SceneError&) {
    refuse_wrong_input(file, expected);
    throw;
  }
}

// The candidate nearest `word` by edit distance, or empty when none is within `max_distance` edits.
std::string closest(std::string_view word, const std::vector<std::string>& candidates, std::size_t max_distance);

// The cost of one run, estimated from the scene before meshing (cli_common.cpp gives the measurements).
struct CostEstimate {
  double blocks = 0, bonds = 0;
  double bytes = 0;    // peak resident memory of one run
  double steps = 0;    // explicit steps of a run that stops after the peak as the paper scene's do
  double seconds = 0;  // wall time of that run on `threads` threads
  int threads = 1;
};
// From the specimen's area and mesh.size (a generated mesh; a user mesh is what it is).
CostEstimate estimate_cost(const Scene& scene);
// One line: "about 2.1e+05 blocks, 3.2e+05 bonds, 1.1 GB, 6 min per run on 2 threads".
std::string describe(const CostEstimate& e);
// Refuses (SceneError naming mesh.size and the estimate, with a coarser mesh.size to use) when `concurrent` runs
// of the scene would need more memory than the machine has available (MemAvailable in /proc/meminfo), unless
// `force`. Unless quiet, prints the estimate under `who` when it is large (over 200 000 blocks, 2 GB or 10
// minutes); small runs print nothing.
void check_cost(const Scene& scene, std::string_view who, int concurrent, bool force, bool quiet);

// Time as a person reads it: "45 s", "12 min", "3.2 h".
std::string duration_text(double seconds);

}  // namespace rbdem::cli
