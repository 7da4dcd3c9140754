// The monitors of a test run. See monitors.hpp.
#include "dem/driver/monitors.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "dem/driver/summary.hpp"
#include "dem/measure.hpp"

namespace rbdem {

LoadRate::LoadRate(const Scene& scene)
    : slow_(scene.loading.platen_velocity), fast_(scene.loading.fast_factor),
      quiet_transits_(scene.loading.quiet_transits),
      wave_speed_(std::sqrt(scene.rock.effective_modulus / (scene.rock.density * scene.numerics.mass_scaling))),
      quiet_breaks_(scene.loading.quiet_breaks), ramp_force_fraction_(scene.loading.ramp_force_fraction),
      density_(scene.rock.density * scene.numerics.mass_scaling), mismatch_stop_(scene.loading.mismatch_stop) {}

void LoadRate::after_step(Simulation& sim) const {
  Platens& platens = *sim.find<Platens>();
  const double dt = sim.dt(), transit = sim.specimen().height() / wave_speed_;
  const double running = double(sim.steps()) * dt;  // the explicit run's time so far
  // The spell is quiet while fewer than quiet_breaks + 1 bonds broke within it: the time since the (quiet_breaks +
  // 1)-th last break (the last one with quiet_breaks = 0). The crack log is in time order.
  const auto& cracks = sim.cracks();
  const std::size_t n = cracks.size(), allowed = std::size_t(quiet_breaks_);
  const double quiet = n <= allowed ? running : std::min(running, sim.time() - cracks[n - 1 - allowed].time);
  const double v = platens.velocity();
  if (ramp_force_fraction_ > 0.0) {
    // The specimen's mass per loaded area is rho H: an acceleration a asks rho H a of the platen stress.
    const double stress = 0.5 * (platens.top_force() + platens.bottom_force()) / platens.area();
    const double change = ramp_force_fraction_ * std::max(stress, 0.0) / (density_ * sim.specimen().height()) * dt;
    double target = quiet > quiet_transits_ * transit ? fast_ * slow_ : slow_;
    if (mismatch_stop_ > 0.0 && stress > 0.0) {
      // The top platen ahead of the bottom one by m of their mean force slows in proportion, to a halt at m = stop.
      const double ahead = (platens.top_force() - platens.bottom_force()) / (platens.area() * stress);
      target *= std::clamp(1.0 - ahead / mismatch_stop_, 0.0, 1.0);
    }
    platens.set_velocity(v < target ? std::min(target, v + change) : std::max(target, v - change));
    return;
  }
  const double rise = (fast_ - 1.0) * slow_ * dt / transit;
  platens.set_velocity(quiet > quiet_transits_ * transit ? std::min(fast_ * slow_, v + rise)
                                                         : std::max(slow_, v - 4.0 * rise));
}

CurvePoint sample_point(const Simulation& sim, const Reading& reading) {
  CurvePoint p;
  p.step = sim.steps();
  p.time = sim.time();
  p.strain = reading.strain;
  p.stress_top = reading.stress_top;
  p.stress_bottom = reading.stress_bottom;
  const Energies e = sim.energies();
  p.kinetic = e.kinetic;
  p.strain_energy = e.strain;
  p.lateral_strain = reading.lateral_strain;
  p.shear_displacement = reading.shear_displacement;
  p.normal_stress = reading.normal_stress;
  p.dilation = reading.dilation;
  const CrackCounts c = count_cracks(sim.cracks());
  p.broken = {c.rock_tensile, c.rock_shear, c.joint_tensile, c.joint_shear};
  return p;
}

Frame make_frame(const Simulation& sim, const Reading& reading, const char* label) {
  Frame f;
  f.step = sim.steps(), f.time = sim.time(), f.strain = reading.strain, f.stress = reading.stress;
  f.label = label;
  f.dim = sim.dimension();
  f.pose = sim.pose();
  f.network = force_network(sim);
  f.cracks = sim.cracks().size();
  return f;
}

void PeakTracker::after_step(const StepView& v) const {
  TestRecord& r = v.record;
  if (!(v.reading.stress > r.peak)) return;
  r.peak = v.reading.stress;
  r.peak_step = v.sim.steps();
  if (v.sim.steps() - r.peak_detail_step >= 100) {
    r.at_peak = sample_point(v.sim, v.reading);
    r.peak_frame = make_frame(v.sim, v.reading, "peak");
    r.peak_detail_step = v.sim.steps();
  } else {
    r.at_peak.step = v.sim.steps(), r.at_peak.time = v.sim.time(), r.at_peak.strain = v.reading.strain;
    r.at_peak.stress_top = v.reading.stress_top, r.at_peak.stress_bottom = v.reading.stress_bottom;
    r.at_peak.lateral_strain = v.reading.lateral_strain;
    r.at_peak.shear_displacement = v.reading.shear_displacement;
    r.at_peak.normal_stress = v.reading.normal_stress, r.at_peak.dilation = v.reading.dilation;
  }
}

void FrameRecorder::after_step(const StepView& v) const {
  if (v.reading.strain < v.record.next_frame) return;
  v.record.frames.push_back(make_frame(v.sim, v.reading, ""));
  v.record.next_frame += interval;
}

bool CurveRecorder::after_step(const StepView& v) const {
  if (v.sim.steps() % v.record.sample_every != 0) return false;
  v.record.curve.push_back(sample_point(v.sim, v.reading));
  return true;
}

std::string watchdog_check(const Simulation& sim, double energy0, const WatchdogCriterion& c, std::string& detail,
                           double& ratio) {
  ratio = 0.0;
  if (detail = sim.non_finite(); !detail.empty()) return "non_finite_state";
  const Energies e = sim.energies();
  const double held = e.kinetic + e.strain;
  double input = energy0;
  std::string work;
  for (const Boundary* b : sim.boundaries()) {
    input += b->work();
    work += fmt::format(" + {:.4g} J of {} work", b->work(), b->name());
  }
  if (!std::isfinite(held)) {
    detail = "the kinetic or strain energy is not finite";
    return "non_finite_state";
  }
  ratio = input > 0 ? held / input : 0.0;
  if (held > c.growth * input + c.floor) {
    detail = fmt::format("kinetic + strain energy {:.4g} J exceeds {:.3g} x the energy put in ({:.4g} J at the start{}) "
                         "+ {:.3g} J",
                         held, c.growth, energy0, work, c.floor);
    return "energy_growth";
  }
  return {};
}

void Watchdog::mark_sound(const Simulation& sim, const TestRecord& record) {
  good_curve = record.curve.size(), good_frames = record.frames.size(), good_cracks = sim.cracks().size();
}

bool Watchdog::check(const Simulation& sim, TestRecord& record, bool regular) {
  double ratio = 0.0;
  cause_ = watchdog_check(sim, record.energy0, criterion_, detail_, ratio);
  if (!cause_.empty()) return false;
  if (regular) record.energy_ratio_max = std::max(record.energy_ratio_max, ratio);
  mark_sound(sim, record);
  return true;
}

bool Checkpointer::after_step(const StepView& v, Watchdog& watchdog, double wall_seconds) {
  const long step = v.sim.steps();
  const bool cancel = step == s_.interrupt_at_step ||
                      (s_.cancel && (step & 255) == 0 && s_.cancel->load(std::memory_order_relaxed));
  bool due = s_.every_steps > 0 && step % s_.every_steps == 0;
  if (!due && s_.every_seconds > 0 && (step & 255) == 0)
    due = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_).count() >= s_.every_seconds;
  if ((due || cancel) && s_.write) {
    if (!watchdog.check(v.sim, v.record, false)) return false;
    TestCheckpoint c;
    c.scene_toml = s_.scene_toml, c.test = s_.test;
    c.state = v.sim.snapshot();
    c.record = v.record;
    c.record.wall_seconds = wall_seconds;
    s_.write(c);
    last_ = std::chrono::steady_clock::now();
  }
  if (cancel) {
    RunCancelled c;
    c.step = step;
    c.checkpointed = bool(s_.write);
    throw c;
  }
  return true;
}

void ProgressReporter::after_step(const StepView& v) const {
  if (!report || v.sim.steps() % 1000 != 0) return;
  report({v.sim.steps(), v.reading.strain, v.reading.stress, v.record.peak, int(v.sim.cracks().size())});
}

}  // namespace rbdem
