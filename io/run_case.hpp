// One test case from a resolved scene to its run folder: the one path the command line (`rbdem ucs`, `triaxial`,
// `brazilian`, ...), the Python module and studies take. It checks the scene for the test (the protocol registry,
// dem/driver/registry.hpp), meshes the specimen (or takes the cached mesh), builds the Simulation, runs the
// protocol through the driver (dem/driver/driver.hpp) and writes the run folder (io/results.hpp).
#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include "dem/driver/driver.hpp"
#include "dem/specimen.hpp"

namespace rbdem::io {

struct CaseOptions {
  std::filesystem::path out;  // the run folder (created); empty: nothing is written
  RunOptions run;             // progress, cancellation, checkpoints, resume, the thread budget
  // numerics.threads for this run, when set, without changing the scene the run folder records (a sweep's case
  // runs with the threads it is given).
  int threads = 0;
  // Threads that compress result.h5 (0: the run's; a sweep gives the cores the case holds when it ends).
  std::function<int()> write_threads;
  // Called once the simulation is built, before the run (a command prints its size).
  std::function<void(const Simulation& sim, bool mesh_cached)> ready;
};

struct CaseRun {
  TestResult result;
  Specimen specimen;          // the specimen's tables (the Python module returns its blocks)
  bool mesh_cached = false;   // the mesh came from the cache
};

// Runs the test `test` of `scene` (resolved and validated) as options say. Throws SceneError when the scene does
// not suit the test, RunCancelled when cancelled (a checkpoint, if any, is written by options.run.checkpoint), and
// what meshing or writing throws. The run folder is written for a run the watchdog stopped too (its summary.json
// says "completed": false).
CaseRun run_case(const std::string& test, const Scene& scene, const CaseOptions& options = {});

}  // namespace rbdem::io
