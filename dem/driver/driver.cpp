// The test driver. See driver.hpp.
#include "dem/driver/driver.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>

#include <fmt/format.h>

#include "dem/driver/monitors.hpp"
#include "dem/driver/registry.hpp"
#include "dem/driver/summary.hpp"

namespace rbdem {

namespace {

using Clock = std::chrono::steady_clock;

// One run: the simulation, its record and its monitors, from start to result.
class TestRun {
 public:
  TestRun(LoadingProtocol& protocol, Simulation& sim, const Scene& scene, const RunOptions& options)
      : protocol_(protocol), sim_(sim), scene_(scene), options_(options), wall0_(Clock::now()),
        rate_(scene),
        frames_{scene.output.frame_strain_interval},
        watchdog_(watchdog_criterion(scene, sim), options.watchdog_every),
        checkpointer_({scene.numerics.checkpoint_every_steps, scene.numerics.checkpoint_every_seconds, options.cancel,
                       options.interrupt_at_step, options.checkpoint, to_toml(scene), protocol.name()}),
        progress_{options.progress} {
    protocol_.install(sim_);
  }

  // A fresh run: the time step, the first sample and frame, the protocol's start. A resumed run: the checkpoint.
  void start() {
    const TestCheckpoint* resume = options_.resume;
    if (resume && (resume->scene_toml != to_toml(scene_) || resume->test != protocol_.name()))
      throw SceneError("the checkpoint was written for another scene or test: resume with the same command, scene "
                       "file, --set options and mesh as the interrupted run, or start afresh without --resume");
    if (resume) {
      rec_ = resume->record;
      sim_.set_dt(rec_.dt);
      sim_.restore(resume->state);
    } else {
      // The protocol's static solves on this thread while a second one (when the run has two) computes the
      // stability limit: both only read the simulation at rest. The solves' products take the run's threads once
      // the limit is done.
      const bool overlap = protocol_.prepares() && sim_.threads() > 1;
      std::atomic<int> static_threads{overlap ? 1 : sim_.threads()};
      auto limit = std::async(overlap ? std::launch::async : std::launch::deferred, [this, overlap, &static_threads] {
        const double l = sim_.stability_limit(300, overlap ? 1 : 0);
        static_threads = sim_.threads();
        return l;
      });
      protocol_.prepare(sim_, static_threads);
      choose_time_step(limit.get());
      rec_.dt = std::min(rec_.dt, protocol_.max_time_step(sim_));
      sim_.set_dt(rec_.dt);
      rec_.sample_every = std::max(1L, protocol_.max_steps(sim_, rec_) / std::max(options_.curve_points, 1));
      const Reading at_rest = protocol_.read(sim_);
      rec_.curve.push_back(sample_point(sim_, at_rest));
      rec_.frames.push_back(make_frame(sim_, at_rest, ""));
      rec_.next_frame = scene_.output.frame_strain_interval;
      rec_.at_peak = rec_.curve.front();
      protocol_.start(sim_, rec_);
      const Energies e = sim_.energies();
      rec_.energy0 = e.kinetic + e.strain;
    }
    rate_.follow(rec_);
    watchdog_.mark_sound(sim_, rec_);
    start_seconds_ = std::chrono::duration<double>(Clock::now() - wall0_).count();
  }

  // Explicit steps until the protocol stops the test, a guard stops the run, or max_strain. Returns false when a
  // guard stopped it.
  bool run() {
    stop_reason_ = "max_strain";
    const long max_explicit = protocol_.max_steps(sim_, rec_);
    // The crack log's strain: the reading after the last step, as nothing moves between steps (protocol.hpp).
    double strain = protocol_.read(sim_).strain;
    while (sim_.steps() < max_explicit) {
      sim_.set_strain_for_log(strain);
      try {
        sim_.step();
      } catch (const InstabilityError&) {
        watchdog_.stop("non_finite_state", "block positions are no longer finite");
        return false;
      }
      if (rate_.adapts()) rate_.after_step(sim_);
      const Reading reading = protocol_.read(sim_);
      strain = reading.strain;
      const StepView view{sim_, reading, rec_};
      peaks_.after_step(view);
      frames_.after_step(view);
      const bool sampled = curve_.after_step(view);
      protocol_.control(sim_, reading, rec_);
      if (std::string reason; protocol_.stop(sim_, reading, rec_, reason)) {
        if (!sampled) rec_.curve.push_back(sample_point(sim_, reading));
        stop_reason_ = reason;
        break;
      }
      if (!watchdog_.after_step(view) || !checkpointer_.after_step(view, watchdog_, wall())) return false;
      progress_.after_step(view);
      // max_explicit counts steps at platen_velocity: a faster platen reaches loading.max_strain before it.
      if (rate_.adapts() && reading.strain >= scene_.loading.max_strain) break;
    }
    // The final state must pass too: a run that blew up between two checks and then met a stop criterion is not
    // done.
    return watchdog_.check(sim_, rec_, true);
  }

  TestResult result(bool completed) {
    const Specimen& specimen = sim_.specimen();
    TestResult r;
    r.test = protocol_.name();
    r.dimension = sim_.dimension();
    r.blocks = specimen.num_blocks(), r.bonds = specimen.num_bonds();
    r.rock_bonds = specimen.count(BondKind::rock), r.joint_bonds = specimen.count(BondKind::joint);
    r.mass_scaling = scene_.numerics.mass_scaling;
    r.threads = sim_.max_threads();
    r.timing = {start_seconds_, sim_.step_times(), sim_.team_counts()};
    r.steps = sim_.steps();
    r.dt = rec_.dt, r.dt_critical = rec_.dt_critical, r.dt_block_estimate = rec_.dt_block_estimate;
    r.elastic_start_strain = rec_.elastic_start_strain;
    r.platen_velocity = rec_.platen_velocity;
    r.energy_ratio_max = rec_.energy_ratio_max;
    r.stop_reason = stop_reason_;
    if (const Jacket* jacket = sim_.find<Jacket>()) r.confining_pressure = jacket->pressure();
    protocol_.results(sim_, rec_, r);
    if (completed) completed_result(r);
    else stopped_result(r);
    crack_statistics(specimen, r);
    r.wall_seconds = wall();
    return r;
  }

 private:
  // The watchdog's absolute floor: the strain energy of the specimen at 1e-5 axial strain, far below any loaded
  // state.
  static WatchdogCriterion watchdog_criterion(const Scene& scene, const Simulation& sim) {
    const Specimen& s = sim.specimen();
    WatchdogCriterion c;
    c.floor = 0.5 * scene.rock.effective_modulus * 1e-10 * s.width() * s.height() * s.thickness;
    return c;
  }

  // numerics.dt when set (refused above the exact stability limit), else dt_safety x that limit.
  void choose_time_step(double critical) {
    rec_.dt_critical = critical;
    rec_.dt_block_estimate = sim_.block_step_estimate();
    const double dt = scene_.numerics.dt;
    if (!(dt > 0.0)) {
      rec_.dt = scene_.numerics.dt_safety * rec_.dt_critical;
      return;
    }
    if (dt > rec_.dt_critical && !options_.allow_supercritical_dt)
      throw SceneError(fmt::format("numerics.dt = {:.4g} s is above the critical time step {:.4g} s of this scene "
                                   "(2 / sqrt(lambda_max) of its {} blocks and their bonds): use numerics.dt <= "
                                   "{:.4g} s, or 0 for automatic ({:.2g} x critical)",
                                   dt, rec_.dt_critical, sim_.num_blocks(), rec_.dt_critical,
                                   scene_.numerics.dt_safety));
    rec_.dt = dt;
  }

  // A run the watchdog stopped keeps its record up to the last sound state; its headline numbers are not results.
  void stopped_result(TestResult& r) const {
    r.completed = false;
    r.watchdog_cause = watchdog_.cause();
    r.watchdog_step = sim_.steps();
    r.watchdog_message = fmt::format(
        "the watchdog stopped the run at step {} (t = {:.4g} s, time step {:.4g} s): {}. The explicit integration is "
        "unstable for this scene: lower numerics.dt_safety (now {:.3g}) or numerics.dt, or check the stiffness and "
        "density values. Results up to step {} (the last sound state) are kept; the peak and modulus are not results",
        sim_.steps(), sim_.time(), rec_.dt, watchdog_.detail(), scene_.numerics.dt_safety,
        watchdog_.good_curve > 0 ? rec_.curve[watchdog_.good_curve - 1].step : 0);
    r.curve.assign(rec_.curve.begin(), rec_.curve.begin() + long(watchdog_.good_curve));
    r.frames.assign(rec_.frames.begin(), rec_.frames.begin() + long(watchdog_.good_frames));
    r.cracks.assign(sim_.cracks().begin(), sim_.cracks().begin() + long(watchdog_.good_cracks));
    r.crack_counts = count_cracks(r.cracks);
    r.cracks_by_material = count_cracks_by_material(r.cracks, sim_.specimen());
    r.stop_reason = "watchdog";
    r.failure_mode = "not_completed";
    r.quasi_static = false;
    r.quasi_static_reason = "the run did not complete";
  }

  // The peak and final frames in order of strain, the peak sample in the curve in order, then summarize().
  void completed_result(TestResult& r) const {
    r.frames = rec_.frames;
    r.frames.push_back(make_frame(sim_, protocol_.read(sim_), "final"));
    if (!rec_.peak_frame.pose.empty()) {
      auto at = std::lower_bound(r.frames.begin(), r.frames.end(), rec_.peak_frame.strain,
                                 [](const Frame& f, double e) { return f.strain < e; });
      r.frames.insert(at, rec_.peak_frame);
    }
    r.curve = rec_.curve;
    auto pos = std::lower_bound(r.curve.begin(), r.curve.end(), rec_.at_peak.strain,
                                [](const CurvePoint& p, double e) { return p.strain < e; });
    if (pos == r.curve.end() || pos->step != rec_.at_peak.step) r.curve.insert(pos, rec_.at_peak);
    r.cracks = sim_.cracks();
    summarize(scene_, sim_.specimen(), protocol_, rec_, r);
    r.lateral_strain_at_peak = rec_.at_peak.lateral_strain;
    protocol_.finish(sim_, rec_, r);
  }

  double wall() const {
    return rec_wall_before() + std::chrono::duration<double>(Clock::now() - wall0_).count();
  }
  double rec_wall_before() const { return options_.resume ? options_.resume->record.wall_seconds : 0.0; }

  LoadingProtocol& protocol_;
  Simulation& sim_;
  const Scene& scene_;
  const RunOptions& options_;
  Clock::time_point wall0_;
  double start_seconds_ = 0;
  TestRecord rec_;
  std::string stop_reason_ = "max_strain";
  LoadRate rate_;
  PeakTracker peaks_;
  FrameRecorder frames_;
  CurveRecorder curve_;
  Watchdog watchdog_;
  Checkpointer checkpointer_;
  ProgressReporter progress_;
};

}  // namespace

TestResult run_test(LoadingProtocol& protocol, Simulation& sim, const Scene& scene, const RunOptions& options) {
  TestRun run(protocol, sim, scene, options);
  run.start();
  const bool completed = run.run();
  return run.result(completed);
}

namespace {

template <class Mesh>
TestResult run_test_on(const std::string& test, const Scene& scene, const Mesh& mesh, const RunOptions& options,
                       const std::function<void(const Simulation&)>& ready) {
  const ProtocolInfo& info = protocol_info(test);
  info.check(scene);
  const auto protocol = info.make(scene, options.curve_points);
  SimulationOptions so;
  so.thread_budget = options.thread_budget;
  const auto sim = Simulation::create(scene, mesh, so);
  if (ready) ready(*sim);
  return run_test(*protocol, *sim, scene, options);
}

}  // namespace

TestResult run_test(const std::string& test, const Scene& scene, const TriMesh& mesh, const RunOptions& options,
                    const std::function<void(const Simulation&)>& ready) {
  return run_test_on(test, scene, mesh, options, ready);
}

TestResult run_test(const std::string& test, const Scene& scene, const TetMesh& mesh, const RunOptions& options,
                    const std::function<void(const Simulation&)>& ready) {
  return run_test_on(test, scene, mesh, options, ready);
}

}  // namespace rbdem
