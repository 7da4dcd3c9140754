// What a test run records as it goes: the curve, the frames of block positions, the peak, the watchdog's
// reference. Plain data. The monitors (dem/driver/monitors.hpp) write it; summarize() (dem/driver/summary.hpp)
// turns it into the result; checkpoints store it next to the engine's ModelState, walking TestRecord::fields().
#pragma once

#include <array>
#include <string>
#include <vector>

namespace rbdem {

struct CurvePoint {
  long step = 0;                            // explicit step; -1 for the points of the static elastic start
  double time = 0, strain = 0;              // s, axial strain = platen displacement / height
  double stress_top = 0, stress_bottom = 0;  // Pa, compression positive, platen force / (width x thickness)
  double kinetic = 0, strain_energy = 0;    // J
  double lateral_strain = 0;                // -, width change / width (compression positive: < 0 when it widens)
  std::array<int, 4> broken{};              // rock tensile, rock shear, joint tensile, joint shear
  double stress() const { return 0.5 * (stress_top + stress_bottom); }
};

// Block positions at one instant (for crack maps on the deformed specimen and ParaView animations).
struct Frame {
  long step = 0;
  double time = 0, strain = 0, stress = 0;
  std::string label;                  // "", "elastic_start", "peak" or "final"
  std::vector<double> x, y, theta;    // per block: centroid (m) and rotation (rad)
  std::size_t cracks = 0;             // cracks logged by then (a prefix of the crack log)
};

// The driver's record of a run: everything a resumed run needs besides the engine's state.
struct TestRecord {
  std::vector<CurvePoint> curve;
  std::vector<Frame> frames;
  // time stepping, fixed when the run starts
  double dt = 0, dt_critical = 0;     // s: the step used, the exact stability limit of the bonded lattice
  double dt_block_estimate = 0;       // s: the block-wise estimate, for comparison
  double elastic_start_strain = 0;    // strain skipped by the static elastic start (0 if none)
  double isotropic_strain = 0;        // axial strain of the static isotropic stage of a confined test (0 if none)
  // sampling
  long sample_every = 1;              // explicit steps between curve samples
  double next_frame = 0;              // axial strain of the next regular frame
  // the peak
  double peak = 0;                    // Pa, the largest mean platen stress so far
  long peak_step = 0, peak_detail_step = -1000;
  CurvePoint at_peak;                 // the sample at the peak (energies at most 100 steps before it)
  Frame peak_frame;                   // block positions at the peak (at most 100 steps before it)
  // the watchdog
  double energy0 = 0;                 // J, kinetic + strain energy when the explicit run began
  double energy_ratio_max = 0;        // max over the regular checks of (kinetic + strain) / (E_0 + platen work)
  double wall_seconds = 0;            // s, wall time spent before this process continued the run

  // The field table of the scalars, as for ModelState: f(name, field) for each; the curve, the frames, at_peak
  // and peak_frame are stored by the checkpoint writer as tables (io/result_h5.cpp).
  template <class F>
  void scalars(F&& f) {
    visit_scalars(*this, f);
  }
  template <class F>
  void scalars(F&& f) const {
    visit_scalars(*this, f);
  }

 private:
  template <class Self, class F>
  static void visit_scalars(Self& r, F& f) {
    f("dt", r.dt);
    f("dt_critical", r.dt_critical);
    f("dt_block_estimate", r.dt_block_estimate);
    f("elastic_start_strain", r.elastic_start_strain);
    f("isotropic_strain", r.isotropic_strain);
    f("sample_every", r.sample_every);
    f("next_frame", r.next_frame);
    f("peak", r.peak);
    f("peak_step", r.peak_step);
    f("peak_detail_step", r.peak_detail_step);
    f("energy0", r.energy0);
    f("energy_ratio_max", r.energy_ratio_max);
    f("wall_seconds", r.wall_seconds);
  }
};

}  // namespace rbdem
