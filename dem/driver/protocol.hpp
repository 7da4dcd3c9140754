// A loading protocol: what the boundaries do and when a test stops. The test driver (dem/driver/driver.hpp) runs
// the explicit steps and the monitors; a protocol supplies the test-specific parts:
//   prepare() the static solves of the start, which only read the engine: the driver runs them while another
//             thread computes the stability limit
//   start()   before the explicit run: boundary set-up and a static start where it is exact
//   read()    after each step: the axial strain and the platen stresses that the curve, the peak and the stop
//             criterion use
//   stop()    whether the test is over, and why
// A new test (uniaxial, confined, Brazilian) is a new protocol; the loop, the recorders, the watchdog, the
// checkpoints and the summary are shared.
#pragma once

#include <atomic>
#include <string>

#include "dem/driver/record.hpp"
#include "dem/driver/result.hpp"
#include "dem/engine.hpp"
#include "dem/scene.hpp"
#include "dem/topology.hpp"

namespace rbdem {

// What a protocol reads off the engine after a step.
struct Reading {
  double strain = 0;                         // axial strain = platen displacement / height
  double stress_top = 0, stress_bottom = 0;  // Pa, platen force / (width x thickness), compression positive
  double stress = 0;                         // Pa, their mean (the curve's stress and the peak)
  double lateral_strain = 0;                 // -, width change / width, compression positive (< 0: it widens)
};

// The specimen's width from its sides: the mean horizontal displacement of the blocks on the right side minus that
// on the left, over the blocks that still hold an intact bond (a fragment that broke off does not count). The sides
// are the boundary edges tagged left and right, or, for a disc, the rim blocks within a tenth of the height of the
// horizontal diameter.
class LateralGauge {
 public:
  explicit LateralGauge(const Topology& topo);
  // -(Delta width) / width: positive when the specimen narrows (compression positive), 0 without sides.
  double strain(const Engine& engine) const;
  // The same for a displacement field u_x per block (a static solution), over all the side blocks.
  double strain_of(const std::vector<double>& ux) const;

 private:
  std::vector<int> left_, right_;
  double width_ = 0;
};

class LoadingProtocol {
 public:
  virtual ~LoadingProtocol() = default;
  // The test's name, as summary.json's "test" gives it.
  virtual std::string name() const = 0;
  // Before the first explicit step of a fresh run (not on resume): set up the boundaries and, where it is exact,
  // bring the engine statically to the state where the explicit run takes over; record the static part of the
  // curve and the sampling interval in `record`.
  virtual void start(Engine& engine, TestRecord& record) = 0;
  // Whether prepare() has static solves to do. The driver then computes the stability limit on a second thread
  // (when it has one) while prepare() runs.
  virtual bool prepares() const { return false; }
  // Before start() of a fresh run, with the engine at rest: the static solves start() needs, kept for it. It must
  // only read the engine; start() does the same solves itself when prepare() was not called. `threads`: the
  // threads the solves may use, read at each solve (StaticOptions::threads; it grows when the stability limit
  // beside them is done).
  virtual void prepare(const Engine& engine, const std::atomic<int>& threads) { (void)engine, (void)threads; }
  // The reading after a step.
  virtual Reading read(const Engine& engine) const = 0;
  // The most explicit steps the run may take (the max_strain limit).
  virtual long max_steps(const Engine& engine, const TestRecord& record) const = 0;
  // After each step (and its samples): true when the test is over; `reason` says why ("post_peak",
  // "post_peak_strain").
  virtual bool stop(const Engine& engine, const Reading& reading, const TestRecord& record,
                    std::string& reason) const = 0;
  // After summarize(): the test's own numbers (and, where it has its own classes, its failure mode).
  virtual void finish(const Engine& engine, const TestRecord& record, TestResult& result) const {
    (void)engine, (void)record, (void)result;
  }
};

}  // namespace rbdem
