// Options every rbdem command shares: the scene file, --set overrides and the --beta/--spacing/--mesh shorthands.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "dem/scene.hpp"

namespace rbdem::cli {

// Exit status of every command: 0 done, 1 the run failed, 2 bad input (scene, options, files),
// 3 a physical check failed (the elastic gate).
enum Exit : int { ok = 0, run_failed = 1, bad_input = 2, check_failed = 3 };

struct SceneOptions {
  std::string scene_file;
  std::vector<std::string> sets;
  std::optional<double> beta, spacing;
  std::string mesh_file;
  bool quiet = false;
  bool force = false;  // skip check_plausible (strengths at or above the modulus: a likely unit mistake)
};

// Adds [scene] positional, --scene, --set, --beta, --spacing, --mesh, --force and --quiet to a command.
void add_scene_options(CLI::App& cmd, SceneOptions& opt);
// Built-in defaults <- scene file <- shorthands <- --set, validated, then checked for likely unit mistakes
// unless --force. Throws SceneError.
Scene resolve_scene(const SceneOptions& opt);
// Prints the resolved scene (TOML) under a heading, unless quiet.
// The --force flag, shared by every command that reads a scene.
void add_force_flag(CLI::App& cmd, bool& force);
void print_scene(const Scene& scene, const SceneOptions& opt);
// The scene the elastic gate checks for a test: the gate meshes rectangles at every dip, so a disc's materials are
// checked on the rectangular specimen of the scene's other keys, without confinement (which does not change the
// elastic moduli of the linear model).
Scene gate_scene(const Scene& scene);

}  // namespace rbdem::cli
