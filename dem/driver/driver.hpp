// The test driver: one loop for every test, on a Simulation of any dimension (dem/simulation.hpp). The protocol
// installs its boundary components (dem/driver/protocol.hpp); the driver chooses the time step, lets the protocol
// start the test, then steps until the protocol says stop or a guard intervenes, calling the monitors
// (dem/driver/monitors.hpp) after each step in a fixed order, and finally hands the record to summarize()
// (dem/driver/summary.hpp). Results are bit-identical at any thread count, and a resumed run ends bit-identical to
// an uninterrupted one.
#pragma once

#include <atomic>
#include <functional>

#include "dem/driver/protocol.hpp"
#include "dem/driver/result.hpp"
#include "dem/scene.hpp"
#include "dem/simulation.hpp"
#include "mesh/trimesh.hpp"

namespace rbdem {

struct RunOptions {
  std::function<void(const RunProgress&)> progress;  // called about every 1000 steps
  int curve_points = 2000;                            // about this many samples up to max_strain
  bool allow_supercritical_dt = false;                // tests only: accept numerics.dt above the critical step
  const std::atomic<bool>* cancel = nullptr;          // checked every 256 steps; set -> RunCancelled
  const std::atomic<int>* thread_budget = nullptr;    // SimulationOptions::thread_budget (numerics.threads is the cap)
  // Called with the run's state every numerics.checkpoint_every_steps steps, every checkpoint_every_seconds of
  // wall time, and on cancel, each time right after the state passed the watchdog. Writing it is the caller's job.
  std::function<void(const TestCheckpoint&)> checkpoint;
  const TestCheckpoint* resume = nullptr;             // continue this run instead of starting (same scene and mesh)
  long interrupt_at_step = -1;                        // tests: behave as if cancel were set at this step
  int watchdog_every = 100;                           // steps between the regular watchdog checks
};

// Runs the test of `protocol` on `sim`, a simulation just built from `scene` (the protocol installs its
// boundaries), or continues options.resume. Throws SceneError for a refused time step or a checkpoint of another
// scene or test, RunCancelled when cancelled. A run the watchdog stops returns with completed = false.
TestResult run_test(LoadingProtocol& protocol, Simulation& sim, const Scene& scene, const RunOptions& options = {});

// The test `test` of the registry (dem/driver/registry.hpp) on a new simulation of `mesh`: checks the scene for the
// test (SceneError), builds the simulation with options.thread_budget, runs. `ready` is called with the simulation
// before the run (a command prints its size).
TestResult run_test(const std::string& test, const Scene& scene, const TriMesh& mesh, const RunOptions& options = {},
                    const std::function<void(const Simulation&)>& ready = nullptr);
// The same on the 3D model of a tetrahedral mesh.
TestResult run_test(const std::string& test, const Scene& scene, const TetMesh& mesh, const RunOptions& options = {},
                    const std::function<void(const Simulation&)>& ready = nullptr);

}  // namespace rbdem
