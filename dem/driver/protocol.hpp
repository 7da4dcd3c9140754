// A loading protocol: what the boundaries do and when a test stops. The test driver (dem/driver/driver.hpp) runs
// the explicit steps and the monitors on a Simulation (dem/simulation.hpp); a protocol supplies the test-specific
// parts:
//   install() the boundary components of the test (platens, a jacket, block groups), on a fresh simulation, for a
//             fresh run and a resumed one alike
//   prepare() the static solves of the start, which only read the simulation: the driver runs them while another
//             thread computes the stability limit
//   start()   before the explicit run: boundary set-up and a static start where it is exact
//   max_time_step()  a bound on the time step where no block's dynamics sets one (every block in a box)
//   read()    after each step: the axial strain and the stresses that the curve, the peak and the stop criterion use
//   control() after each step: what the boundaries do next (their speeds, servos, pressures; nothing moves before
//             the next step, so the driver's reading after a step also holds before the next)
//   stop()    whether the test is over, and why
//   results() the test's own numbers (summary.json), and finish() its failure classes where it has its own
// A protocol is one file in dem/driver/protocols/ with one line in the registry (dem/driver/registry.cpp), or one
// registered at run time (register_protocol); the loop, the recorders, the watchdog, the checkpoints, the summary
// and the writers are shared.
#pragma once

#include <atomic>
#include <limits>
#include <string>

#include "dem/driver/record.hpp"
#include "dem/driver/result.hpp"
#include "dem/scene.hpp"
#include "dem/simulation.hpp"

namespace rbdem {

// What a protocol reads off the simulation after a step.
struct Reading {
  double strain = 0;                         // axial strain = platen closure / height
  double stress_top = 0, stress_bottom = 0;  // Pa, the curve's stress of each platen's force, compression positive
  double stress = 0;                         // Pa, their mean (the curve's stress and the peak)
  double lateral_strain = 0;                 // -, width change / width, compression positive (< 0: it widens)
  // The direct shear test's (CurvePoint::shear_displacement, normal_stress, dilation); 0 for the other tests.
  double shear_displacement = 0, normal_stress = 0, dilation = 0;  // m, Pa, m
};

class LoadingProtocol {
 public:
  virtual ~LoadingProtocol() = default;
  // The test's name, as summary.json's "test" gives it.
  virtual std::string name() const = 0;
  // Installs the test's boundary components on `sim` (before anything else reads it).
  virtual void install(Simulation& sim) = 0;
  // Before the first explicit step of a fresh run (not on resume): set up the boundaries and, where it is exact,
  // bring the simulation statically to the state where the explicit run takes over; record the static part of the
  // curve and the sampling interval in `record`.
  virtual void start(Simulation& sim, TestRecord& record) = 0;
  // Whether prepare() has static solves to do. The driver then computes the stability limit on a second thread
  // (when it has one) while prepare() runs.
  virtual bool prepares() const { return false; }
  // Before start() of a fresh run, with the simulation at rest: the static solves start() needs, kept for it. It
  // must only read the simulation; start() does the same solves itself when prepare() was not called. `threads`:
  // the threads the solves may use, read at each solve (StaticOptions::threads; it grows when the stability limit
  // beside them is done).
  virtual void prepare(const Simulation& sim, const std::atomic<int>& threads) { (void)sim, (void)threads; }
  // The largest time step the test can resolve (s), for a test whose loaded parts all move as prescribed, so that
  // no block's dynamics bounds the step (rbdem shear's boxes); +inf: the stability limit alone. The driver takes the
  // smaller of this and the step it chose, before start().
  virtual double max_time_step(const Simulation& sim) const {
    (void)sim;
    return std::numeric_limits<double>::infinity();
  }
  // The reading after a step.
  virtual Reading read(const Simulation& sim) const = 0;
  // After each step's reading and monitors: what the protocol changes before the next step (a platen's speed or
  // servo, a group's velocity: a cyclic or a hold test). What it keeps must live in the simulation's boundaries or
  // the record, so that a resumed run goes on the same.
  virtual void control(Simulation& sim, const Reading& reading, const TestRecord& record) {
    (void)sim, (void)reading, (void)record;
  }
  // The most explicit steps the run may take (the max_strain limit).
  virtual long max_steps(const Simulation& sim, const TestRecord& record) const = 0;
  // After each step (and its samples): true when the test is over; `reason` says why ("post_peak",
  // "post_peak_strain").
  virtual bool stop(const Simulation& sim, const Reading& reading, const TestRecord& record,
                    std::string& reason) const = 0;
  // The stress the stop criteria and the signals measure the peak from (a confined test's sigma_3; 0 otherwise).
  virtual double stress_floor() const { return 0.0; }
  // Whether the lateral strain is the specimen's width change under axial load, so that Poisson's ratio and the
  // crack damage stress are read from it (not for a disc's diameter under diametral load).
  virtual bool lateral_signals() const { return true; }
  // The test's own numbers (TestResult::own), for every run, one the watchdog stopped included.
  virtual void results(const Simulation& sim, const TestRecord& record, TestResult& result) const {
    (void)sim, (void)record, (void)result;
  }
  // After summarize() of a completed run: the test's own failure classes, where it has them.
  virtual void finish(const Simulation& sim, const TestRecord& record, TestResult& result) const {
    (void)sim, (void)record, (void)result;
  }
};

}  // namespace rbdem
