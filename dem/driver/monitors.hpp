// The monitors of a test run: small objects the driver calls after every explicit step, in a fixed order.
//   loading    LoadRate: the top platen's speed while the specimen is quiet (loading.fast_factor)
//   recorders  PeakTracker, FrameRecorder, CurveRecorder: write the run's TestRecord
//   guards     Watchdog (the state stays finite and the energy bounded), Checkpointer (periodic checkpoints and
//              cancellation), ProgressReporter
// Each owns one job and its own settings; what must survive a restart lives in the TestRecord, never in a monitor.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <string>

#include "dem/driver/protocol.hpp"
#include "dem/driver/record.hpp"
#include "dem/driver/result.hpp"
#include "dem/simulation.hpp"

namespace rbdem {

// A curve sample and a frame of block poses at the simulation's current state.
CurvePoint sample_point(const Simulation& sim, const Reading& reading);
Frame make_frame(const Simulation& sim, const Reading& reading, const char* label);

// What a monitor sees after a step.
struct StepView {
  const Simulation& sim;
  const Reading& reading;
  TestRecord& record;
};

// loading.fast_factor: the top platen closes faster while no bond breaks. Once no bond has broken for
// loading.quiet_transits times the time a compression wave takes to cross the specimen (H / sqrt(E* / rho), rho
// with its mass scaling) since the explicit run began or the last break, the platen's speed rises towards
// fast_factor x loading.platen_velocity, from nothing to the full rise in one such time; the step after a break it
// falls back, reaching loading.platen_velocity within a quarter of one. The speed lives in the platens' state (the
// snapshot) and the time of the last break in the crack log, so a resumed run goes on exactly as the
// uninterrupted one, and the run is the same at any thread count. docs/model.md, "Platens", says why and what it
// costs in accuracy.
// The platen that follows the rock's state extends it: a quiet spell may hold loading.quiet_breaks breaks; with
// loading.ramp_force_fraction eps > 0 the speed moves towards its target by at most eps sigma dt / (rho H) a step
// (the specimen's inertial force within eps of the platen force sigma A), and with loading.mismatch_stop s > 0 the
// target is scaled by 1 - m / s (within 0 and 1), m the top platen's force ahead of the bottom one's over their mean.
// It reads only the platen forces of the step and the crack log, so the same holds.
class LoadRate {
 public:
  explicit LoadRate(const Scene& scene);
  bool adapts() const { return fast_ > 1.0 || mismatch_stop_ > 0.0; }
  // The run's base speed (m/s) when the protocol set it (TestRecord::platen_velocity > 0, loading.
  // transit_strain_fraction): the fast speed is fast_factor times it.
  void follow(const TestRecord& record) {
    if (record.platen_velocity > 0.0) slow_ = record.platen_velocity;
  }
  void after_step(Simulation& sim) const;

 private:
  double slow_ = 0, fast_ = 1, quiet_transits_ = 0, wave_speed_ = 0;  // m/s, -, -, m/s
  int quiet_breaks_ = 0;
  double ramp_force_fraction_ = 0, density_ = 0;  // -, kg/m^3 (with its mass scaling)
  double mismatch_stop_ = 0;
};

// The peak of the mean platen stress; its sample and frame refreshed at most every 100 steps of a rising curve
// (energies and positions cost a pass over every bond and block), so the stored peak state is at most 100 steps
// before the peak.
struct PeakTracker {
  void after_step(const StepView& v) const;
};

// Block positions every `interval` of axial strain.
struct FrameRecorder {
  double interval = 0;
  void after_step(const StepView& v) const;
};

// A curve sample every record.sample_every steps. Returns whether it sampled this step.
struct CurveRecorder {
  bool after_step(const StepView& v) const;
};

// The watchdog's energy criterion (docs/reliability.md): with E_0 the kinetic + strain energy when the explicit
// run began and W the work of the top platen since, a sound run has E_kin + E_strain <= E_0 + W (the rest went
// into damping and friction). The run is stopped when E_kin + E_strain > growth (E_0 + W) + floor.
struct WatchdogCriterion {
  double growth = 1.5;   // -, allowed excess over the energy put in (integration error is far below)
  double floor = 0.0;    // J, absolute allowance: the strain energy of the specimen at 1e-5 axial strain
};
// Empty when the simulation's state is sound; otherwise the cause ("non_finite_state" or "energy_growth") and, in
// `detail`, what was seen. `ratio` receives (E_kin + E_strain) / (E_0 + W), W the boundaries' work.
std::string watchdog_check(const Simulation& sim, double energy0, const WatchdogCriterion& c, std::string& detail,
                           double& ratio);

// Checks the state every `every` steps and before every checkpoint; remembers the last sound state (the sizes of
// the curve, the frames and the crack log then), which is what a stopped run keeps.
class Watchdog {
 public:
  Watchdog(WatchdogCriterion criterion, int every) : criterion_(criterion), every_(every) {}
  // Records the current record and crack log as sound (the start of the explicit run).
  void mark_sound(const Simulation& sim, const TestRecord& record);
  // The regular check: false when the run must stop.
  bool after_step(const StepView& v) {
    return v.sim.steps() % every_ != 0 || check(v.sim, v.record, true);
  }
  // One check; `regular` checks also update the largest energy ratio (deterministic: regular steps only).
  bool check(const Simulation& sim, TestRecord& record, bool regular);
  // Marks the run stopped for a cause seen outside the checks (an InstabilityError).
  void stop(std::string cause, std::string detail) { cause_ = std::move(cause), detail_ = std::move(detail); }
  const std::string& cause() const { return cause_; }
  const std::string& detail() const { return detail_; }
  std::size_t good_curve = 0, good_frames = 0, good_cracks = 0;

 private:
  WatchdogCriterion criterion_;
  int every_ = 100;
  std::string cause_, detail_;
};

// Checkpoints every `every_steps` steps and every `every_seconds` of wall time, and on cancellation, each time
// right after the state passed the watchdog; a cancelled run then throws RunCancelled.
class Checkpointer {
 public:
  struct Settings {
    long every_steps = 0;
    double every_seconds = 0;
    const std::atomic<bool>* cancel = nullptr;  // read every 256 steps
    long interrupt_at_step = -1;                // tests: behave as if cancel were set at this step
    std::function<void(const TestCheckpoint&)> write;
    std::string scene_toml, test;
  };
  explicit Checkpointer(Settings s) : s_(std::move(s)), last_(std::chrono::steady_clock::now()) {}
  // False when the watchdog refused the state before a checkpoint (the run must stop).
  bool after_step(const StepView& v, Watchdog& watchdog, double wall_seconds);

 private:
  Settings s_;
  std::chrono::steady_clock::time_point last_;
};

// Progress every 1000 steps.
struct ProgressReporter {
  std::function<void(const RunProgress&)> report;
  void after_step(const StepView& v) const;
};

}  // namespace rbdem
