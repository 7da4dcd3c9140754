// The test driver. See driver.hpp.
#include "dem/driver/driver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

#include "dem/driver/monitors.hpp"
#include "dem/driver/summary.hpp"
#include "dem/static_solve.hpp"

namespace rbdem {

namespace {

// The time step: numerics.dt when set (refused above the exact stability limit), else dt_safety x that limit.
void choose_time_step(const Engine& engine, const Scene& scene, const Topology& topo, bool allow_supercritical,
                      TestRecord& rec) {
  rec.dt_critical = stability_limit(engine);
  rec.dt_block_estimate = engine.critical_step();
  if (scene.numerics.dt > 0.0) {
    if (scene.numerics.dt > rec.dt_critical && !allow_supercritical)
      throw SceneError(fmt::format("numerics.dt = {:.4g} s is above the critical time step {:.4g} s of this scene "
                                   "(2 / sqrt(lambda_max) of its {} blocks and their bonds): use numerics.dt <= "
                                   "{:.4g} s, or 0 for automatic ({:.2g} x critical)",
                                   scene.numerics.dt, rec.dt_critical, topo.blocks.size(), rec.dt_critical,
                                   scene.numerics.dt_safety));
    rec.dt = scene.numerics.dt;
  } else {
    rec.dt = scene.numerics.dt_safety * rec.dt_critical;
  }
}

}  // namespace

TestResult run_test(LoadingProtocol& protocol, const Scene& scene, const Topology& topo, const RunOptions& options) {
  const auto wall0 = std::chrono::steady_clock::now();
  EngineOptions engine_options = EngineOptions::from_scene(scene);
  engine_options.thread_budget = options.thread_budget;
  Engine engine(topo, scene, engine_options);
  const TestCheckpoint* resume = options.resume;
  if (resume && (resume->scene_toml != to_toml(scene) || resume->test != protocol.name()))
    throw SceneError("the checkpoint was written for another scene or test: resume with the same command, scene "
                     "file, --set options and mesh as the interrupted run, or start afresh without --resume");
  TestRecord rec;
  if (resume) {
    rec = resume->record;
  } else {
    choose_time_step(engine, scene, topo, options.allow_supercritical_dt, rec);
  }
  engine.set_dt(rec.dt);
  TestResult r;
  r.test = protocol.name();
  r.blocks = topo.blocks.size();
  r.bonds = topo.bonds.size();
  r.rock_bonds = topo.count(BondKind::rock);
  r.joint_bonds = topo.count(BondKind::joint);
  r.mass_scaling = scene.numerics.mass_scaling;
  r.threads = engine.max_threads();

  const double H = engine.specimen_height(), W = engine.specimen_width(), t = engine.thickness();
  const double frame_interval = scene.output.frame_strain_interval;
  if (!resume) {
    const long max_steps = protocol.max_steps(engine, rec);
    rec.sample_every = std::max(1L, max_steps / std::max(options.curve_points, 1));
    const Reading at_rest = protocol.read(engine);
    rec.curve.push_back(sample_point(engine, at_rest));
    rec.frames.push_back(make_frame(engine, at_rest, ""));
    rec.next_frame = frame_interval;
    rec.at_peak = rec.curve.front();
    protocol.start(engine, rec);
    const Energies e = engine.energies();
    rec.energy0 = e.kinetic + e.strain;
  } else {
    engine.restore(resume->engine);
  }

  // The monitors, in the order they run after each step.
  const PeakTracker peak_tracker;
  const FrameRecorder frame_recorder{frame_interval};
  const CurveRecorder curve_recorder;
  // The watchdog's absolute floor: the strain energy of the specimen at 1e-5 axial strain, far below any loaded
  // state.
  WatchdogCriterion criterion;
  criterion.floor = 0.5 * scene.rock.effective_modulus * 1e-10 * W * H * t;
  Watchdog watchdog(criterion, options.watchdog_every);
  watchdog.mark_sound(engine, rec);
  const double wall_before = rec.wall_seconds;  // wall time of the run before it was resumed
  auto wall = [&]() {
    return wall_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  };
  Checkpointer checkpointer({scene.numerics.checkpoint_every_steps, scene.numerics.checkpoint_every_seconds,
                             options.cancel, options.interrupt_at_step, options.checkpoint, to_toml(scene),
                             protocol.name()});
  const ProgressReporter progress{options.progress};

  r.stop_reason = "max_strain";
  bool stopped = false;  // by the watchdog
  const long max_explicit = protocol.max_steps(engine, rec);
  while (engine.steps() < max_explicit) {
    engine.set_strain_for_log(protocol.read(engine).strain);
    try {
      engine.step();
    } catch (const InstabilityError&) {
      watchdog.stop("non_finite_state", "block positions are no longer finite");
      stopped = true;
      break;
    }
    const Reading reading = protocol.read(engine);
    const StepView view{engine, reading, rec};
    peak_tracker.after_step(view);
    frame_recorder.after_step(view);
    const bool sampled = curve_recorder.after_step(view);
    std::string reason;
    if (protocol.stop(engine, reading, rec, reason)) {
      if (!sampled) rec.curve.push_back(sample_point(engine, reading));
      r.stop_reason = reason;
      break;
    }
    if (!watchdog.after_step(view) || !checkpointer.after_step(view, watchdog, wall())) {
      stopped = true;
      break;
    }
    progress.after_step(view);
  }
  // The final state must pass too: a run that blew up between two checks and then met a stop criterion is not done.
  if (!stopped && !watchdog.check(engine, rec, true)) stopped = true;
  r.steps = engine.steps();
  r.dt = rec.dt, r.dt_critical = rec.dt_critical, r.dt_block_estimate = rec.dt_block_estimate;
  r.elastic_start_strain = rec.elastic_start_strain;
  r.energy_ratio_max = rec.energy_ratio_max;
  if (stopped) {
    r.completed = false;
    r.watchdog_cause = watchdog.cause();
    r.watchdog_step = engine.steps();
    r.watchdog_message = fmt::format(
        "the watchdog stopped the run at step {} (t = {:.4g} s, time step {:.4g} s): {}. The explicit integration is "
        "unstable for this scene: lower numerics.dt_safety (now {:.3g}) or numerics.dt, or check the stiffness and "
        "density values. Results up to step {} (the last sound state) are kept; the peak and modulus are not results",
        engine.steps(), engine.time(), rec.dt, watchdog.detail(), scene.numerics.dt_safety,
        watchdog.good_curve > 0 ? rec.curve[watchdog.good_curve - 1].step : 0);
    r.curve.assign(rec.curve.begin(), rec.curve.begin() + long(watchdog.good_curve));
    r.frames.assign(rec.frames.begin(), rec.frames.begin() + long(watchdog.good_frames));
    r.cracks.assign(engine.cracks().begin(), engine.cracks().begin() + long(watchdog.good_cracks));
    r.crack_counts = count_cracks(r.cracks);
    r.stop_reason = "watchdog";
    r.failure_mode = "not_completed";
    r.quasi_static = false;
    r.quasi_static_reason = "the run did not complete";
    r.wall_seconds = wall();
    return r;
  }
  // The peak and final frames, in order of strain; the peak sample in the curve, in order.
  r.frames = std::move(rec.frames);
  r.frames.push_back(make_frame(engine, protocol.read(engine), "final"));
  if (!rec.peak_frame.x.empty()) {
    auto at = std::lower_bound(r.frames.begin(), r.frames.end(), rec.peak_frame.strain,
                               [](const Frame& f, double e) { return f.strain < e; });
    r.frames.insert(at, rec.peak_frame);
  }
  r.curve = std::move(rec.curve);
  auto pos = std::lower_bound(r.curve.begin(), r.curve.end(), rec.at_peak.strain,
                              [](const CurvePoint& p, double e) { return p.strain < e; });
  if (pos == r.curve.end() || pos->step != rec.at_peak.step) r.curve.insert(pos, rec.at_peak);
  r.cracks = engine.cracks();
  summarize(scene, topo, rec, r);
  r.wall_seconds = wall();
  return r;
}

}  // namespace rbdem
