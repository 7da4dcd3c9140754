// The uniaxial compression test: the specimen between two platens, the top one closing at constant speed,
// run until the stress falls below stop_fraction of the peak after the peak (or max_strain). Plain results,
// no file I/O (io/ writes them).
#pragma once

#include <array>
#include <atomic>
#include <stdexcept>
#include <functional>
#include <string>
#include <vector>

#include "dem/engine.hpp"
#include "dem/scene.hpp"
#include "dem/topology.hpp"

namespace rbdem {

struct CurvePoint {
  long step = 0;                            // explicit step; -1 for the points of the static elastic start
  double time = 0, strain = 0;              // s, axial strain = platen displacement / height
  double stress_top = 0, stress_bottom = 0;  // Pa, compression positive, platen force / (width x thickness)
  double kinetic = 0, strain_energy = 0;    // J
  std::array<int, 4> broken{};              // rock tensile, rock shear, joint tensile, joint shear
  double stress() const { return 0.5 * (stress_top + stress_bottom); }
};

// Block positions at one instant (for crack maps on the deformed specimen and ParaView animations).
struct Frame {
  long step = 0;
  double time = 0, strain = 0, stress = 0;
  std::string label;                  // "", "peak" or "final"
  std::vector<double> x, y, theta;    // per block: centroid (m) and rotation (rad)
  std::size_t cracks = 0;             // cracks logged by then (a prefix of the crack log)
};

struct CrackCounts {
  int rock_tensile = 0, rock_shear = 0, joint_tensile = 0, joint_shear = 0;
  int total() const { return rock_tensile + rock_shear + joint_tensile + joint_shear; }
};
CrackCounts count_cracks(const std::vector<Crack>& cracks);

// Failure mode from the crack log, in the seed paper's three classes plus one:
//   a joint broken along at least half its length, mostly in shear, with a large resolved shear stress on it
//   (tau / sigma = sin(2 dip) / 2 > 1/4: 15 < dip < 75 deg) -> "shear_slip_along_joints"
//   a joint broken along at least half its length otherwise -> "splitting_along_layers"
//   no joint broken through: rock cracks, by length, mostly tensile -> splitting, "splitting_along_layers" when the
//   layers are steep (dip >= 60 deg, cracks parallel to them) else "splitting_across_layers";
//   mostly shear -> "shear_through_rock"; and "intact" when nothing broke.
std::string classify_failure(const std::vector<Crack>& cracks, const Topology& topo, double dip_deg);

// Dip (0..90 deg from the horizontal) of the principal axis of the crack positions, weighted by crack length:
// near 90 for axial splitting, near 45 + phi/2 for a shear band, the joint dip for slip along a joint.
double crack_band_angle_deg(const std::vector<Crack>& cracks, const Topology& topo);

struct UcsResult {
  double peak_stress = 0;       // Pa (mean of the two platens)
  double strain_at_peak = 0;
  double youngs_modulus = 0;    // Pa, secant at 50 % of the peak
  double platen_force_mismatch = 0;  // max |F_top - F_bottom| / mean while loading (20 to 95 % of the peak)
  double platen_force_mismatch_at_peak = 0;
  double kinetic_to_strain_at_peak = 0;
  std::vector<CurvePoint> curve;
  std::vector<Crack> cracks;
  std::vector<Frame> frames;    // every output.frame_strain_interval, plus the peak and the final state
  CrackCounts crack_counts;
  double crack_band_angle_deg = 0;  // principal direction of the crack positions, from the horizontal
  double tensile_fraction = 0;      // tensile share of the crack length
  std::string failure_mode;
  std::string stop_reason;      // "post_peak" (stress dropped) | "post_peak_strain" | "max_strain"
  long steps = 0;
  double dt = 0, dt_critical = 0;   // s: the step used, the exact stability limit of the bonded lattice
  double dt_block_estimate = 0;     // s: THEORY.md 5's block-wise estimate, for comparison
  double mass_scaling = 1.0;
  double wall_seconds = 0;
  double elastic_start_strain = 0;  // strain skipped by the static elastic start (0 if none)
  std::size_t blocks = 0, bonds = 0, rock_bonds = 0, joint_bonds = 0;
  // The watchdog (docs/reliability.md): false when the run was stopped because its state became non-finite or
  // its energy grew without work input. Then the curve, cracks and frames end at the last state that passed the
  // check and the headline numbers (peak, modulus, failure mode) are not results.
  bool completed = true;
  std::string watchdog_cause;       // "non_finite_state" | "energy_growth" (empty when completed)
  std::string watchdog_message;     // what happened, at which step, and the fix
  long watchdog_step = -1;          // the step at which the watchdog stopped the run
  double energy_ratio_max = 0;      // max over the regular checks of (kinetic + strain) / (E_0 + platen work)
  // Quasi-static verdict (THEORY.md 5): platen forces agree and the kinetic energy is small while loading.
  double kinetic_to_strain_loading = 0;  // max kinetic / strain energy on the loading branch (20 to 95 % of peak)
  bool quasi_static = true;
  std::string quasi_static_reason;  // why not (empty when quasi-static)
};

struct UcsProgress {
  long step;
  double strain, stress, peak;
  int cracks;
};

// Thrown by run_ucs when UcsOptions::cancel was set (SIGINT in a sweep or a single run): no result exists for the
// run. With a checkpoint callback, the state at `step` was handed to it first (checkpointed = true).
struct RunCancelled : std::runtime_error {
  RunCancelled() : std::runtime_error("run cancelled") {}
  long step = -1;
  bool checkpointed = false;
};

// Everything a UCS run needs to continue where it stopped: the engine's full state and the driver's (curve, frames
// and peak tracking so far). Plain data; io/checkpoint.hpp stores it in checkpoint.h5.
struct UcsCheckpoint {
  std::string scene_toml;        // the resolved scene of the run (a resume with another scene is refused)
  Engine::Snapshot engine;
  UcsResult partial;             // curve, frames, dt, dt_critical, dt_block_estimate, elastic_start_strain, wall
  long sample_every = 1;
  double next_frame = 0, peak = 0;
  long peak_step = 0, peak_detail_step = -1000;
  CurvePoint at_peak;
  Frame peak_frame;
  double energy0 = 0;            // J, the watchdog's reference: kinetic + strain energy when the explicit run began
};

struct UcsOptions {
  std::function<void(const UcsProgress&)> progress;  // called about every 1000 steps
  int curve_points = 2000;                           // about this many samples up to max_strain
  bool allow_supercritical_dt = false;               // tests only: accept numerics.dt above the critical step
  const std::atomic<bool>* cancel = nullptr;         // checked every 256 steps; set -> RunCancelled
  const std::atomic<int>* thread_budget = nullptr;   // EngineOptions::thread_budget (numerics.threads is the cap)
  // Called with the run's state every numerics.checkpoint_every_steps steps, every checkpoint_every_seconds of
  // wall time, and on cancel, each time right after the state passed the watchdog. Writing it is the caller's job.
  std::function<void(const UcsCheckpoint&)> checkpoint;
  const UcsCheckpoint* resume = nullptr;             // continue this run instead of starting (same scene and mesh)
  long interrupt_at_step = -1;                       // tests: behave as if cancel were set at this step
  int watchdog_every = 100;                          // steps between the regular watchdog checks
};

// The watchdog's energy criterion (docs/reliability.md): with E_0 the kinetic + strain energy when the explicit
// run began and W the work of the top platen since, a sound run has E_kin + E_strain <= E_0 + W (the rest went
// into damping and friction). The run is stopped when E_kin + E_strain > growth (E_0 + W) + floor.
struct WatchdogCriterion {
  double growth = 1.5;   // -, allowed excess over the energy put in (integration error is far below)
  double floor = 0.0;    // J, absolute allowance: the strain energy of the specimen at 1e-5 axial strain
};
// Empty when the engine's state is sound; otherwise the cause ("non_finite_state" or "energy_growth") and, in
// `detail`, what was seen. `ratio` receives (E_kin + E_strain) / (E_0 + W).
std::string watchdog_check(const Engine& engine, double energy0, const WatchdogCriterion& c, std::string& detail,
                           double& ratio);

// Runs the test (or continues options.resume). Throws SceneError for a refused time step or a checkpoint of another
// scene, RunCancelled when cancelled. A run the watchdog stops returns with completed = false.
UcsResult run_ucs(const Scene& scene, const Topology& topo, const UcsOptions& options = {});

}  // namespace rbdem
