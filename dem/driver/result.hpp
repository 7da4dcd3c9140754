// The result of a test run, as summarize() (dem/driver/summary.hpp) makes it from the run's record. Plain data,
// no file I/O (io/results.hpp writes it).
#pragma once

#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "dem/driver/record.hpp"
#include "dem/driver/signals.hpp"
#include "dem/records.hpp"
#include "dem/snapshot.hpp"
#include "dem/team.hpp"

namespace rbdem {

struct CrackCounts {
  int rock_tensile = 0, rock_shear = 0, joint_tensile = 0, joint_shear = 0;
  int total() const { return rock_tensile + rock_shear + joint_tensile + joint_shear; }
};

// The bonds of one material (dem/materials.hpp) and how many of them broke, by mode.
struct MaterialCracks {
  std::string material;  // "rock", "joint", "joint2" or "rock2"
  int bonds = 0, tensile = 0, shear = 0;
};

// A number of the protocol's own (dem/driver/protocol.hpp), written into summary.json under `key`. `measured`: a
// result of the run (null in summary.json when the run did not complete), else a setting or a count.
struct ResultValue {
  std::string key;
  double value = 0;
  bool measured = true;
};

struct TestResult {
  std::string test = "ucs";     // the protocol's name (dem/driver/registry.hpp)
  int dimension = 2;
  double peak_stress = 0;       // Pa: the peak of the curve's stress (sigma_1 in compression; the Brazilian test's
                                // tensile stress 2 P / (pi D t))
  double strain_at_peak = 0;
  double youngs_modulus = 0;    // Pa, secant at 50 % of the peak
  double platen_force_mismatch = 0;  // max |F_top - F_bottom| / mean while loading (20 to 95 % of the peak)
  double platen_force_mismatch_at_peak = 0;
  double kinetic_to_strain_at_peak = 0;
  std::vector<CurvePoint> curve;
  std::vector<Crack> cracks;
  std::vector<Frame> frames;    // every output.frame_strain_interval, plus the peak and the final state
  CrackCounts crack_counts;
  std::vector<MaterialCracks> cracks_by_material;  // the materials the specimen has, in material id order
  double crack_band_angle_deg = 0;  // principal direction of the crack positions, from the horizontal (3D: the dip
                                    // of the crack band's plane)
  double crack_band_dip_direction_deg = std::numeric_limits<double>::quiet_NaN();  // 3D: the band plane's
  CrackRose crack_rose;             // 3D: cracks by dip and dip direction (empty in 2D)
  double tensile_fraction = 0;      // tensile share of the crack length
  std::string failure_mode;
  // deg: the joints' dip the run had: the scene's joint_set.dip_deg, or for a user mesh the dip measured from its
  // joint edges (joint_dip_deg); NaN before the summary
  double joint_dip_deg = std::numeric_limits<double>::quiet_NaN();
  std::string stop_reason;      // "post_peak" (stress dropped) | "post_peak_strain" | "max_strain" | "watchdog"
  long steps = 0;
  double dt = 0, dt_critical = 0;   // s: the step used, the exact stability limit of the bonded lattice
  double dt_block_estimate = 0;     // s: the block-wise estimate (docs/theory.md, section 8), for comparison
  double mass_scaling = 1.0;
  double wall_seconds = 0;
  double elastic_start_strain = 0;  // strain skipped by the static elastic start (0 if none)
  double platen_velocity = 0;       // m/s, the top platen's speed of the explicit run (0: a test without platens)
  double lateral_strain_at_peak = 0;  // -, compression positive (< 0: the specimen widened)
  // The signals of the test (dem/driver/signals.hpp, docs/theory.md, section 10); NaN where not defined.
  double poisson_ratio_at_half_peak = undefined_signal;  // -, tangent -d eps_l / d eps_a at 40-60 % of the peak
  double crack_initiation_stress = undefined_signal;     // Pa, onset of sustained cracking
  double crack_damage_stress = undefined_signal;         // Pa, at the reversal of the volumetric strain
  double residual_stress = undefined_signal;             // Pa, mean stress at the end of a run past the peak
  std::vector<CrackRateBin> crack_rate;                  // cracks per unit axial strain, binned
  std::vector<Fragment> fragments;                       // at the end of the run, largest first
  double confining_pressure = 0;    // Pa, sigma_3: the jacket's pressure (0 without a jacket)
  std::vector<ResultValue> own;     // the protocol's own numbers, in its order
  std::vector<Cycle> cycles;        // rbdem cyclic: one row per loading-unloading cycle (empty for other tests)
  std::size_t blocks = 0, bonds = 0, rock_bonds = 0, joint_bonds = 0;
  // The protocol's own value `key` (NaN when it has none).
  double own_value(const std::string& key) const {
    for (const ResultValue& v : own)
      if (v.key == key) return v.value;
    return std::numeric_limits<double>::quiet_NaN();
  }
  int threads = 1;                  // the OpenMP threads the engine ran on (at most)
  // Where the wall time went and how the thread team followed the cores free (the run log; not in summary.json,
  // which holds only what identical runs share).
  struct Timing {
    double start_seconds = 0;  // s: before the first step (static start, stability limit, the first records)
    StepTimes steps;           // in the explicit steps (dem/team.hpp)
    TeamSize::Counts team;
  } timing;
  // The watchdog (docs/reliability.md): false when the run was stopped because its state became non-finite or
  // its energy grew without work input. Then the curve, cracks and frames end at the last state that passed the
  // check and the headline numbers (peak, modulus, failure mode) are not results.
  bool completed = true;
  std::string watchdog_cause;       // "non_finite_state" | "energy_growth" (empty when completed)
  std::string watchdog_message;     // what happened, at which step, and the fix
  long watchdog_step = -1;          // the step at which the watchdog stopped the run
  double energy_ratio_max = 0;      // max over the regular checks of (kinetic + strain) / (E_0 + platen work)
  // Quasi-static verdict (docs/theory.md, section 8): platen forces agree and the kinetic energy is small while
  // loading.
  double kinetic_to_strain_loading = 0;  // max kinetic / strain energy on the loading branch (20 to 95 % of peak)
  bool quasi_static = true;
  std::string quasi_static_reason;  // why not (empty when quasi-static)
};

struct RunProgress {
  long step;
  double strain, stress, peak;
  int cracks;
};

// Thrown by run_test when RunOptions::cancel was set (SIGINT in a sweep or a single run): no result exists for the
// run. With a checkpoint callback, the state at `step` was handed to it first (checkpointed = true).
struct RunCancelled : std::runtime_error {
  RunCancelled() : std::runtime_error("run cancelled") {}
  long step = -1;
  bool checkpointed = false;
};

// Everything a run needs to continue where it stopped: the simulation's snapshot and the driver's record. Plain
// data; io/checkpoint.hpp stores it in checkpoint.h5.
struct TestCheckpoint {
  std::string scene_toml;        // the resolved scene of the run (a resume with another scene is refused)
  std::string test;              // the protocol's name
  Snapshot state;
  TestRecord record;
  long steps() const { return state.has("steps") ? state.get<long>("steps") : 0; }
};

}  // namespace rbdem
