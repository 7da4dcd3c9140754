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
};

struct UcsProgress {
  long step;
  double strain, stress, peak;
  int cracks;
};

// Thrown by run_ucs when UcsOptions::cancel was set (SIGINT in a sweep): no result exists for the run.
struct RunCancelled : std::runtime_error {
  RunCancelled() : std::runtime_error("run cancelled") {}
};

struct UcsOptions {
  std::function<void(const UcsProgress&)> progress;  // called about every 1000 steps
  int curve_points = 2000;                           // about this many samples up to max_strain
  bool allow_supercritical_dt = false;               // tests only: accept numerics.dt above the critical step
  const std::atomic<bool>* cancel = nullptr;         // checked every 256 steps; set -> RunCancelled
};

// Runs the test. Throws SceneError for a refused time step, InstabilityError if the run diverges.
UcsResult run_ucs(const Scene& scene, const Topology& topo, const UcsOptions& options = {});

}  // namespace rbdem
