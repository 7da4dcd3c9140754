// Uniaxial compression driver. See ucs.hpp.
#include "dem/ucs.hpp"

#include "dem/static_solve.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include <fmt/format.h>

namespace rbdem {

namespace {
// The quasi-static verdict's limits (THEORY.md 5 asks for about 1 % force agreement; explicit samples on a rising
// branch of a coarse specimen scatter by a few per cent even at quasi-static rates, hence 5 %).
constexpr double quasi_static_force_mismatch = 0.05;
constexpr double quasi_static_kinetic_ratio = 0.05;
}  // namespace

CrackCounts count_cracks(const std::vector<Crack>& cracks) {
  CrackCounts c;
  for (const auto& k : cracks) {
    const bool shear = k.mode == BreakMode::shear;
    if (k.kind == BondKind::rock) (shear ? c.rock_shear : c.rock_tensile)++;
    else (shear ? c.joint_shear : c.joint_tensile)++;
  }
  return c;
}

std::string classify_failure(const std::vector<Crack>& cracks, const Topology& topo, double dip_deg) {
  if (cracks.empty()) return "intact";
  // Per joint (the interface between two layers): its length and how much of it broke, by mode.
  std::map<std::pair<int, int>, std::array<double, 3>> joints;  // total, broken in shear, broken in tension
  const auto& N = topo.bonds;
  auto joint_of = [&](std::size_t b) {
    const int a = topo.blocks.layer[std::size_t(N.i[b])], c = topo.blocks.layer[std::size_t(N.j[b])];
    return std::pair<int, int>{std::min(a, c), std::max(a, c)};
  };
  for (std::size_t b = 0; b < N.size(); ++b)
    if (N.kind[b] == BondKind::joint) joints[joint_of(b)][0] += N.length[b];
  double rock_t = 0, rock_s = 0;
  for (const auto& k : cracks) {
    const std::size_t b = std::size_t(k.bond);
    const bool shear = k.mode == BreakMode::shear;
    if (k.kind == BondKind::joint) joints[joint_of(b)][shear ? 1 : 2] += N.length[b];
    else (shear ? rock_s : rock_t) += N.length[b];
  }
  // A joint broken along most of its length failed as a plane. It slid if it was broken in shear and the load
  // resolves a large shear stress on it: tau / sigma = sin(2 beta) / 2 > 1/4, i.e. 15 < beta < 75 deg. At steeper
  // and flatter dips a broken joint has opened: splitting along the layers (the paper's cleavage at 75-90 deg).
  const bool shear_loaded = dip_deg > 15.0 && dip_deg < 75.0;
  bool slipped = false, opened = false;
  for (const auto& [id, len] : joints) {
    if (len[1] + len[2] < 0.5 * len[0]) continue;
    if (len[1] >= len[2] && shear_loaded) slipped = true;
    else opened = true;
  }
  if (slipped) return "shear_slip_along_joints";
  if (opened) return "splitting_along_layers";
  if (rock_t >= rock_s) return dip_deg >= 60.0 ? "splitting_along_layers" : "splitting_across_layers";
  return "shear_through_rock";
}

double crack_band_angle_deg(const std::vector<Crack>& cracks, const Topology& topo) {
  double w = 0, mx = 0, my = 0;
  for (const auto& k : cracks) {
    const double L = topo.bonds.length[std::size_t(k.bond)];
    w += L, mx += L * k.x, my += L * k.y;
  }
  if (w <= 0) return 0.0;
  mx /= w, my /= w;
  double sxx = 0, syy = 0, sxy = 0;
  for (const auto& k : cracks) {
    const double L = topo.bonds.length[std::size_t(k.bond)];
    sxx += L * (k.x - mx) * (k.x - mx), syy += L * (k.y - my) * (k.y - my), sxy += L * (k.x - mx) * (k.y - my);
  }
  const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy) * 180.0 / 3.14159265358979323846;  // major axis
  return std::abs(angle);
}

std::string watchdog_check(const Engine& engine, double energy0, const WatchdogCriterion& c, std::string& detail,
                           double& ratio) {
  ratio = 0.0;
  for (std::size_t b = 0; b < engine.blocks.size(); ++b) {
    const BlockState& s = engine.blocks.state[b];
    if (!(std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.theta) && std::isfinite(s.vx) &&
          std::isfinite(s.vy) && std::isfinite(s.omega))) {
      detail = fmt::format("block {} has a non-finite position or velocity", b);
      return "non_finite_state";
    }
  }
  const Energies e = engine.energies();
  const double held = e.kinetic + e.strain, input = energy0 + e.work_platen;
  if (!std::isfinite(held)) {
    detail = "the kinetic or strain energy is not finite";
    return "non_finite_state";
  }
  ratio = input > 0 ? held / input : 0.0;
  if (held > c.growth * input + c.floor) {
    detail = fmt::format("kinetic + strain energy {:.4g} J exceeds {:.3g} x the energy put in ({:.4g} J at the start "
                         "+ {:.4g} J of platen work) + {:.3g} J",
                         held, c.growth, energy0, e.work_platen, c.floor);
    return "energy_growth";
  }
  return {};
}

UcsResult run_ucs(const Scene& scene, const Topology& topo, const UcsOptions& options) {
  const auto wall0 = std::chrono::steady_clock::now();
  EngineOptions engine_options = EngineOptions::from_scene(scene);
  engine_options.thread_budget = options.thread_budget;
  Engine engine(topo, scene, engine_options);
  const UcsCheckpoint* resume = options.resume;
  if (resume && resume->scene_toml != to_toml(scene))
    throw SceneError("the checkpoint was written for another scene: resume with the same scene file, --set options "
                     "and mesh as the interrupted run, or start afresh without --resume");
  UcsResult r;
  if (resume) {
    r.curve = resume->partial.curve, r.frames = resume->partial.frames;
    r.dt = resume->partial.dt, r.dt_critical = resume->partial.dt_critical;
    r.dt_block_estimate = resume->partial.dt_block_estimate;
    r.elastic_start_strain = resume->partial.elastic_start_strain;
  }
  r.blocks = topo.blocks.size();
  r.bonds = topo.bonds.size();
  r.rock_bonds = topo.count(BondKind::rock);
  r.joint_bonds = topo.count(BondKind::joint);
  r.mass_scaling = scene.numerics.mass_scaling;
  if (!resume) {
    r.dt_critical = stability_limit(engine);
    r.dt_block_estimate = engine.critical_step();
    if (scene.numerics.dt > 0.0) {
      if (scene.numerics.dt > r.dt_critical && !options.allow_supercritical_dt)
        throw SceneError(fmt::format("numerics.dt = {:.4g} s is above the critical time step {:.4g} s of this scene "
                                     "(2 / sqrt(lambda_max) of its {} blocks and their bonds): use numerics.dt <= "
                                     "{:.4g} s, or 0 for automatic ({:.2g} x critical)",
                                     scene.numerics.dt, r.dt_critical, topo.blocks.size(), r.dt_critical,
                                     scene.numerics.dt_safety));
      r.dt = scene.numerics.dt;
    } else {
      r.dt = scene.numerics.dt_safety * r.dt_critical;
    }
  }
  engine.set_dt(r.dt);

  const double H = engine.specimen_height(), W = engine.specimen_width(), t = engine.thickness();
  const double area = W * t;
  const double v = scene.loading.platen_velocity;
  const long max_steps = long(std::ceil(scene.loading.max_strain * H / (v * r.dt)));
  long sample_every = std::max(1L, max_steps / std::max(options.curve_points, 1));

  auto sample = [&]() {
    CurvePoint p;
    p.step = engine.steps();
    p.time = engine.time();
    p.strain = engine.platen_displacement() / H;
    p.stress_top = engine.top_force() / area;
    p.stress_bottom = engine.bottom_force() / area;
    const Energies e = engine.energies();
    p.kinetic = e.kinetic;
    p.strain_energy = e.strain;
    const CrackCounts c = count_cracks(engine.cracks());
    p.broken = {c.rock_tensile, c.rock_shear, c.joint_tensile, c.joint_shear};
    return p;
  };
  auto frame = [&](const char* label) {
    Frame f;
    f.step = engine.steps(), f.time = engine.time(), f.strain = engine.platen_displacement() / H;
    f.stress = 0.5 * (engine.top_force() + engine.bottom_force()) / area;
    f.label = label;
    f.x.resize(engine.blocks.size()), f.y.resize(engine.blocks.size()), f.theta.resize(engine.blocks.size());
    for (std::size_t b = 0; b < engine.blocks.size(); ++b) {
      const BlockState& s = engine.blocks.state[b];
      f.x[b] = s.x, f.y[b] = s.y, f.theta[b] = s.theta;
    }
    f.cracks = engine.cracks().size();
    return f;
  };
  const double frame_interval = scene.output.frame_strain_interval;
  double next_frame = 0.0;
  if (!resume) {
    r.curve.push_back(sample());
    r.frames.push_back(frame(""));
    next_frame = frame_interval;
  }

  // Elastic start: the model is linear until the first bond breaks, so solve that part statically and hand over
  // to the explicit run at a fraction of the first-break load (model only what the scene needs).
  if (scene.numerics.elastic_start && !resume) {
    const StaticResult st = solve_static(engine, {1e-6 * H, false, 30});
    const double max_factor = scene.loading.max_strain * H / st.platen_displacement;
    const double factor = std::min(scene.numerics.elastic_start_fraction * st.first_break_factor, 0.5 * max_factor);
    if (factor > 0 && std::isfinite(factor)) {
      const int n = 20;
      for (int k = 1; k <= n; ++k) {
        const double f = factor * double(k) / double(n);
        CurvePoint p;
        p.step = -1;
        p.strain = f * st.platen_displacement / H;
        p.time = f * st.platen_displacement / v;
        p.stress_top = f * st.top_force / area;
        p.stress_bottom = f * st.bottom_force / area;
        r.curve.push_back(p);
      }
      apply_static_state(engine, st, factor, v);
      r.elastic_start_strain = factor * st.platen_displacement / H;
      // Sample the explicit part densely: about curve_points / 5 samples per first-break strain.
      const double per_step = v * r.dt / H;
      sample_every = std::max(1L, long(r.elastic_start_strain / (0.2 * options.curve_points) / per_step));
      r.frames.push_back(frame("elastic_start"));
      r.frames.back().stress = 0.5 * factor * (st.top_force + st.bottom_force) / area;  // no step computed forces yet
      next_frame = (std::floor(r.elastic_start_strain / frame_interval) + 1.0) * frame_interval;
    }
  }

  double peak = 0;
  long peak_step = 0, peak_detail_step = -1000;
  Frame peak_frame;
  CurvePoint at_peak = r.curve.front();
  // The watchdog: the energy held when the explicit run begins, and the criterion's absolute floor (the strain
  // energy of the specimen at 1e-5 axial strain, far below any loaded state).
  WatchdogCriterion criterion;
  criterion.floor = 0.5 * scene.rock.effective_modulus * 1e-10 * W * H * t;
  double energy0 = 0.0;
  double wall_before = 0.0;  // wall time of the run before it was resumed
  if (resume) {
    engine.restore(resume->engine);
    sample_every = resume->sample_every, next_frame = resume->next_frame, peak = resume->peak;
    peak_step = resume->peak_step, peak_detail_step = resume->peak_detail_step;
    at_peak = resume->at_peak, peak_frame = resume->peak_frame;
    energy0 = resume->energy0;
    r.energy_ratio_max = resume->partial.energy_ratio_max;
    wall_before = resume->partial.wall_seconds;
  } else {
    const Energies e = engine.energies();
    energy0 = e.kinetic + e.strain;
  }
  // The last state that passed the watchdog: what a stopped run keeps.
  std::size_t good_curve = r.curve.size(), good_frames = r.frames.size(), good_cracks = engine.cracks().size();
  std::string cause, detail;
  auto check = [&](bool regular) {
    double ratio = 0.0;
    cause = watchdog_check(engine, energy0, criterion, detail, ratio);
    if (!cause.empty()) return false;
    if (regular) r.energy_ratio_max = std::max(r.energy_ratio_max, ratio);  // deterministic: regular steps only
    good_curve = r.curve.size(), good_frames = r.frames.size(), good_cracks = engine.cracks().size();
    return true;
  };
  auto make_checkpoint = [&]() {
    UcsCheckpoint c;
    c.scene_toml = to_toml(scene);
    c.engine = engine.snapshot();
    c.partial.curve = r.curve, c.partial.frames = r.frames;
    c.partial.dt = r.dt, c.partial.dt_critical = r.dt_critical, c.partial.dt_block_estimate = r.dt_block_estimate;
    c.partial.elastic_start_strain = r.elastic_start_strain;
    c.partial.energy_ratio_max = r.energy_ratio_max;
    c.partial.wall_seconds =
        wall_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    c.sample_every = sample_every, c.next_frame = next_frame, c.peak = peak;
    c.peak_step = peak_step, c.peak_detail_step = peak_detail_step;
    c.at_peak = at_peak, c.peak_frame = peak_frame;
    c.energy0 = energy0;
    return c;
  };
  const long ckpt_steps = scene.numerics.checkpoint_every_steps;
  const double ckpt_seconds = scene.numerics.checkpoint_every_seconds;
  auto last_ckpt = std::chrono::steady_clock::now();

  r.stop_reason = "max_strain";
  bool stopped = false;  // by the watchdog
  const long max_explicit = long(std::ceil((scene.loading.max_strain - r.elastic_start_strain) * H / (v * r.dt)));
  while (engine.steps() < max_explicit) {
    engine.strain_for_log = engine.platen_displacement() / H;
    try {
      engine.step();
    } catch (const InstabilityError&) {
      cause = "non_finite_state", detail = "block positions are no longer finite";
      stopped = true;
      break;
    }
    const double stress = 0.5 * (engine.top_force() + engine.bottom_force()) / area;
    const double strain = engine.platen_displacement() / H;
    if (stress > peak) {
      peak = stress;
      peak_step = engine.steps();
      // Energies and block positions cost a pass over every bond and block: refresh them at most every 100 steps
      // of a rising curve (the stored peak state is then at most 100 steps before the peak).
      if (engine.steps() - peak_detail_step >= 100) {
        at_peak = sample();
        peak_frame = frame("peak");
        peak_detail_step = engine.steps();
      } else {
        at_peak.step = engine.steps(), at_peak.time = engine.time(), at_peak.strain = strain;
        at_peak.stress_top = engine.top_force() / area, at_peak.stress_bottom = engine.bottom_force() / area;
      }
    }
    if (strain >= next_frame) {
      r.frames.push_back(frame(""));
      next_frame += frame_interval;
    }
    const bool record = engine.steps() % sample_every == 0;
    if (record) r.curve.push_back(sample());
    if (!engine.cracks().empty() && engine.steps() > peak_step) {
      const bool dropped = stress < scene.loading.stop_fraction * peak;
      const bool residual = strain > (1.0 + scene.loading.post_peak_strain) * at_peak.strain;
      if (dropped || residual) {
        if (!record) r.curve.push_back(sample());
        r.stop_reason = dropped ? "post_peak" : "post_peak_strain";
        break;
      }
    }
    if (engine.steps() % options.watchdog_every == 0 && !check(true)) {
      stopped = true;
      break;
    }
    const bool cancel = engine.steps() == options.interrupt_at_step ||
                        (options.cancel && (engine.steps() & 255) == 0 &&
                         options.cancel->load(std::memory_order_relaxed));
    bool due = ckpt_steps > 0 && engine.steps() % ckpt_steps == 0;
    if (!due && ckpt_seconds > 0 && (engine.steps() & 255) == 0)
      due = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_ckpt).count() >= ckpt_seconds;
    if ((due || cancel) && options.checkpoint) {
      if (!check(false)) {
        stopped = true;
        break;
      }
      options.checkpoint(make_checkpoint());
      last_ckpt = std::chrono::steady_clock::now();
    }
    if (cancel) {
      RunCancelled c;
      c.step = engine.steps();
      c.checkpointed = bool(options.checkpoint);
      throw c;
    }
    if (options.progress && engine.steps() % 1000 == 0)
      options.progress({engine.steps(), engine.platen_displacement() / H, stress, peak, int(engine.cracks().size())});
  }
  // The final state must pass too: a run that blew up between two checks and then met a stop criterion is not done.
  if (!stopped && !check(true)) stopped = true;
  r.steps = engine.steps();
  if (stopped) {
    r.completed = false;
    r.watchdog_cause = cause;
    r.watchdog_step = engine.steps();
    r.watchdog_message = fmt::format(
        "the watchdog stopped the run at step {} (t = {:.4g} s, time step {:.4g} s): {}. The explicit integration is "
        "unstable for this scene: lower numerics.dt_safety (now {:.3g}) or numerics.dt, or check the stiffness and "
        "density values. Results up to step {} (the last sound state) are kept; the peak and modulus are not results",
        engine.steps(), engine.time(), r.dt, detail, scene.numerics.dt_safety,
        good_curve > 0 ? r.curve[good_curve - 1].step : 0);
    r.curve.resize(good_curve);
    r.frames.resize(good_frames);
    r.cracks.assign(engine.cracks().begin(), engine.cracks().begin() + long(good_cracks));
    r.crack_counts = count_cracks(r.cracks);
    r.stop_reason = "watchdog";
    r.failure_mode = "not_completed";
    r.quasi_static = false;
    r.quasi_static_reason = "the run did not complete";
    r.wall_seconds = wall_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    return r;
  }
  // The peak and final frames, in order of strain.
  r.frames.push_back(frame("final"));
  if (!peak_frame.x.empty()) {
    auto at = std::lower_bound(r.frames.begin(), r.frames.end(), peak_frame.strain,
                               [](const Frame& f, double e) { return f.strain < e; });
    r.frames.insert(at, std::move(peak_frame));
  }
  // Keep the peak sample in the curve, in order.
  auto pos = std::lower_bound(r.curve.begin(), r.curve.end(), at_peak.strain,
                              [](const CurvePoint& p, double e) { return p.strain < e; });
  if (pos == r.curve.end() || pos->step != at_peak.step) r.curve.insert(pos, at_peak);

  r.peak_stress = peak;
  r.strain_at_peak = at_peak.strain;
  const double mean_force = 0.5 * (at_peak.stress_top + at_peak.stress_bottom);
  r.platen_force_mismatch_at_peak =
      mean_force > 0 ? std::abs(at_peak.stress_top - at_peak.stress_bottom) / mean_force : 0.0;
  // The quasi-static check: platen forces agree while loading (explicit samples on the rising branch between 20 %
  // and 95 % of the peak; the first explicit sample if the elastic start skipped them). At the peak a brittle
  // failure is dynamic by nature: that value is reported separately.
  r.platen_force_mismatch = 0.0;
  const CurvePoint* first_explicit = nullptr;
  bool any = false;
  for (const auto& p : r.curve) {
    if (p.step <= 0 || p.strain >= at_peak.strain) continue;
    if (!first_explicit) first_explicit = &p;
    if (p.stress() < 0.2 * peak || p.stress() > 0.95 * peak) continue;
    any = true;
    r.platen_force_mismatch = std::max(r.platen_force_mismatch, std::abs(p.stress_top - p.stress_bottom) / p.stress());
    if (p.strain_energy > 0) r.kinetic_to_strain_loading = std::max(r.kinetic_to_strain_loading, p.kinetic / p.strain_energy);
  }
  if (!any && first_explicit && first_explicit->stress() > 0) {
    r.platen_force_mismatch = std::abs(first_explicit->stress_top - first_explicit->stress_bottom) / first_explicit->stress();
    if (first_explicit->strain_energy > 0) r.kinetic_to_strain_loading = first_explicit->kinetic / first_explicit->strain_energy;
  }
  r.kinetic_to_strain_at_peak = at_peak.strain_energy > 0 ? at_peak.kinetic / at_peak.strain_energy : 0.0;
  // The verdict (THEORY.md 5): platen forces within 5 % and kinetic energy below 5 % of the strain energy while
  // loading. Brittle failure at the peak is dynamic by nature and does not count against it.
  {
    std::vector<std::string> why;
    if (!(r.platen_force_mismatch <= quasi_static_force_mismatch))
      why.push_back(fmt::format("platen forces differ by {:.1f} % while loading (limit {:.0f} %)",
                                100.0 * r.platen_force_mismatch, 100.0 * quasi_static_force_mismatch));
    if (!(r.kinetic_to_strain_loading <= quasi_static_kinetic_ratio))
      why.push_back(fmt::format("kinetic energy is {:.1f} % of the strain energy while loading (limit {:.0f} %)",
                                100.0 * r.kinetic_to_strain_loading, 100.0 * quasi_static_kinetic_ratio));
    if (peak <= 0) why.push_back("the platens carried no load");
    r.quasi_static = why.empty();
    for (std::size_t k = 0; k < why.size(); ++k) r.quasi_static_reason += (k ? "; " : "") + why[k];
    if (!r.quasi_static) r.quasi_static_reason += ": lower loading.platen_velocity or raise numerics.damping";
  }
  // Secant modulus at 50 % of the peak, interpolated on the pre-peak curve.
  for (std::size_t k = 1; k < r.curve.size() && r.curve[k].strain <= at_peak.strain; ++k) {
    const double s0 = r.curve[k - 1].stress(), s1 = r.curve[k].stress();
    if (s1 >= 0.5 * peak && s0 < 0.5 * peak) {
      const double f = (0.5 * peak - s0) / (s1 - s0);
      const double e = r.curve[k - 1].strain + f * (r.curve[k].strain - r.curve[k - 1].strain);
      r.youngs_modulus = e > 0 ? 0.5 * peak / e : 0.0;
      break;
    }
  }
  r.cracks = engine.cracks();
  r.crack_counts = count_cracks(r.cracks);
  r.failure_mode = classify_failure(r.cracks, topo, scene.joint_set.dip_deg);
  r.crack_band_angle_deg = crack_band_angle_deg(r.cracks, topo);
  {
    double t_len = 0, all = 0;
    for (const auto& k : r.cracks) {
      const double L = topo.bonds.length[std::size_t(k.bond)];
      all += L;
      if (k.mode == BreakMode::tensile) t_len += L;
    }
    r.tensile_fraction = all > 0 ? t_len / all : 0.0;
  }
  r.wall_seconds = wall_before + std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

}  // namespace rbdem
