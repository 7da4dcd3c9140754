// The uniaxial compression test: the specimen between two platens, the top one closing at constant speed,
// run until the stress falls below stop_fraction of the peak after the peak (or max_strain). Plain results,
// no file I/O (io/ writes them).
#pragma once

#include <array>
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

struct CrackCounts {
  int rock_tensile = 0, rock_shear = 0, joint_tensile = 0, joint_shear = 0;
  int total() const { return rock_tensile + rock_shear + joint_tensile + joint_shear; }
};
CrackCounts count_cracks(const std::vector<Crack>& cracks);

// Failure mode from the crack log, weighted by crack length: "splitting_across_layers" (rock cracks dominate),
// "shear_slip_along_joints" (joint cracks dominate, mostly shear), "splitting_along_layers" (joint cracks
// dominate, mostly tensile), or "intact" when nothing broke.
std::string classify_failure(const std::vector<Crack>& cracks, const Topology& topo);

struct UcsResult {
  double peak_stress = 0;       // Pa (mean of the two platens)
  double strain_at_peak = 0;
  double youngs_modulus = 0;    // Pa, secant at 50 % of the peak
  double platen_force_mismatch = 0;  // |F_top - F_bottom| / mean at the peak
  double kinetic_to_strain_at_peak = 0;
  std::vector<CurvePoint> curve;
  std::vector<Crack> cracks;
  CrackCounts crack_counts;
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

struct UcsOptions {
  std::function<void(const UcsProgress&)> progress;  // called about every 1000 steps
  int curve_points = 2000;                           // about this many samples up to max_strain
  bool allow_supercritical_dt = false;               // tests only: accept numerics.dt above the critical step
};

// Runs the test. Throws SceneError for a refused time step, InstabilityError if the run diverges.
UcsResult run_ucs(const Scene& scene, const Topology& topo, const UcsOptions& options = {});

}  // namespace rbdem
