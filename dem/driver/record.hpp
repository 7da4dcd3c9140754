// What a test run records as it goes: the curve, the frames of block poses, the peak, the watchdog's reference.
// Plain data; the records themselves (CurvePoint, Frame) are declared in dem/records.hpp. The monitors
// (dem/driver/monitors.hpp) write it; summarize() (dem/driver/summary.hpp) turns it into the result; checkpoints
// store it next to the simulation's snapshot, walking TestRecord::scalars() and the records' field tables.
#pragma once

#include <string>
#include <vector>

#include "dem/records.hpp"

namespace rbdem {

// The driver's record of a run: everything a resumed run needs besides the engine's state.
struct TestRecord {
  std::vector<CurvePoint> curve;
  std::vector<Frame> frames;
  // time stepping, fixed when the run starts
  double dt = 0, dt_critical = 0;     // s: the step used, the exact stability limit of the bonded lattice
  double dt_block_estimate = 0;       // s: the block-wise estimate, for comparison
  double elastic_start_strain = 0;    // strain skipped by the static elastic start (0 if none)
  double preload_strain = 0;          // axial strain of a static preload before the axial loading (the isotropic
                                      // stage of a confined test; 0 if none)
  double platen_velocity = 0;         // m/s, the top platen's speed in the explicit run: loading.platen_velocity, or
                                      // set from the rock by loading.transit_strain_fraction (0 before the start)
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
    f("preload_strain", r.preload_strain);
    f("platen_velocity", r.platen_velocity);
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
