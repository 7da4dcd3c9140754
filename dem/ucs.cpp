// Uniaxial compression driver. See ucs.hpp.
#include "dem/ucs.hpp"

#include "dem/static_solve.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>

namespace rbdem {

CrackCounts count_cracks(const std::vector<Crack>& cracks) {
  CrackCounts c;
  for (const auto& k : cracks) {
    const bool shear = k.mode == BreakMode::shear;
    if (k.kind == BondKind::rock) (shear ? c.rock_shear : c.rock_tensile)++;
    else (shear ? c.joint_shear : c.joint_tensile)++;
  }
  return c;
}

std::string classify_failure(const std::vector<Crack>& cracks, const Topology& topo) {
  double rock = 0, joint_t = 0, joint_s = 0;
  for (const auto& k : cracks) {
    const double L = topo.bonds.length[k.bond];
    if (k.kind == BondKind::rock) rock += L;
    else (k.mode == BreakMode::shear ? joint_s : joint_t) += L;
  }
  if (rock + joint_t + joint_s == 0) return "intact";
  if (joint_t + joint_s >= rock) return joint_s >= joint_t ? "shear_slip_along_joints" : "splitting_along_layers";
  return "splitting_across_layers";
}

UcsResult run_ucs(const Scene& scene, const Topology& topo, const UcsOptions& options) {
  const auto wall0 = std::chrono::steady_clock::now();
  Engine engine(topo, scene, EngineOptions::from_scene(scene));
  UcsResult r;
  r.blocks = topo.blocks.size();
  r.bonds = topo.bonds.size();
  r.rock_bonds = topo.count(BondKind::rock);
  r.joint_bonds = topo.count(BondKind::joint);
  r.mass_scaling = scene.numerics.mass_scaling;
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
  engine.set_dt(r.dt);

  const double H = engine.specimen_height(), W = engine.specimen_width(), t = engine.thickness();
  const double area = W * t;
  const double v = scene.loading.platen_velocity;
  const long max_steps = long(std::ceil(scene.loading.max_strain * H / (v * r.dt)));
  const long sample_every = std::max(1L, max_steps / std::max(options.curve_points, 1));

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
  r.curve.push_back(sample());

  // Elastic start: the model is linear until the first bond breaks, so solve that part statically and hand over
  // to the explicit run at a fraction of the first-break load (model only what the scene needs).
  if (scene.numerics.elastic_start) {
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
    }
  }

  double peak = 0;
  long peak_step = 0;
  CurvePoint at_peak = r.curve.front();
  r.stop_reason = "max_strain";
  const long max_explicit = long(std::ceil((scene.loading.max_strain - r.elastic_start_strain) * H / (v * r.dt)));
  while (engine.steps() < max_explicit) {
    engine.strain_for_log = engine.platen_displacement() / H;
    engine.step();
    const double stress = 0.5 * (engine.top_force() + engine.bottom_force()) / area;
    const double strain = engine.platen_displacement() / H;
    if (stress > peak) {
      peak = stress;
      peak_step = engine.steps();
      at_peak = sample();
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
    if (options.progress && engine.steps() % 1000 == 0)
      options.progress({engine.steps(), engine.platen_displacement() / H, stress, peak, int(engine.cracks().size())});
  }
  // Keep the peak sample in the curve, in order.
  auto pos = std::lower_bound(r.curve.begin(), r.curve.end(), at_peak.strain,
                              [](const CurvePoint& p, double e) { return p.strain < e; });
  if (pos == r.curve.end() || pos->step != at_peak.step) r.curve.insert(pos, at_peak);

  r.peak_stress = peak;
  r.strain_at_peak = at_peak.strain;
  const double mean_force = 0.5 * (at_peak.stress_top + at_peak.stress_bottom);
  r.platen_force_mismatch = mean_force > 0 ? std::abs(at_peak.stress_top - at_peak.stress_bottom) / mean_force : 0.0;
  r.kinetic_to_strain_at_peak = at_peak.strain_energy > 0 ? at_peak.kinetic / at_peak.strain_energy : 0.0;
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
  r.failure_mode = classify_failure(r.cracks, topo);
  r.steps = engine.steps();
  r.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return r;
}

}  // namespace rbdem
