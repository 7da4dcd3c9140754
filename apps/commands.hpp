// The rbdem subcommands. Each registers its options on the CLI11 app and returns a runner.
#pragma once

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

#include "dem/driver/registry.hpp"

namespace rbdem::cli {

using Runner = std::function<int()>;

Runner add_mesh_command(CLI::App& app);
// rbdem <test>: one test of a protocol of the registry (apps/cmd_test.cpp; dem/driver/registry.hpp).
Runner add_test_command(CLI::App& app, const ProtocolInfo& test);
Runner add_sweep_command(CLI::App& app);
Runner add_calibrate_command(CLI::App& app);
Runner add_verify_command(CLI::App& app);
Runner add_elastic_command(CLI::App& app);  // without deal.II: the FE columns empty, Amadei decides
// The main job with no arguments.
// The default dip study; with realizations > 1, that many meshes per dip (mesh.seed 0 .. realizations - 1) into
// runs/default_realizations, with the mean, sd and 95 % interval of each dip's peak.
int run_default_job(int realizations = 1);

}  // namespace rbdem::cli
