// Tests between two platens. See platen_test.hpp.
#include "dem/driver/platen_test.hpp"

#include <algorithm>
#include <cmath>

#include "dem/driver/monitors.hpp"

namespace rbdem {

void PlatenTest::install(Simulation& sim) {
  sim.add_platens({scene_.loading.platen_velocity, scene_.loading.platen_friction});
}

Reading PlatenTest::read(const Simulation& sim) const {
  const Platens& p = platens(sim);
  Reading r;
  r.strain = p.closure() / sim.specimen().height();
  r.stress_top = stress_of(p.top_force(), sim);
  r.stress_bottom = stress_of(p.bottom_force(), sim);
  r.stress = stress_of(0.5 * (p.top_force() + p.bottom_force()), sim);
  r.lateral_strain = sim.lateral_strain();
  return r;
}

long PlatenTest::max_steps(const Simulation& sim, const TestRecord& record) const {
  const double H = sim.specimen().height(), v = velocity(record);
  return long(std::ceil((scene_.loading.max_strain - record.elastic_start_strain) * H / (v * record.dt)));
}

StaticResult PlatenTest::closure_solve(const Simulation& sim, const std::atomic<int>* threads) const {
  StaticOptions so;
  so.threads = threads;
  so.platen_displacement = 1e-6 * sim.specimen().height();
  return sim.solve_static(so);
}

void PlatenTest::prepare(const Simulation& sim, const std::atomic<int>& threads) {
  if (scene_.numerics.elastic_start) prepared_closure_ = closure_solve(sim, &threads);
}

void PlatenTest::start(Simulation& sim, TestRecord& record) {
  record.platen_velocity = scene_.loading.platen_velocity;  // start_along sets the rock's speed where asked
  if (!scene_.numerics.elastic_start) return;
  const StaticResult closure = prepared_closure_ ? std::move(*prepared_closure_) : closure_solve(sim);
  prepared_closure_.reset();
  start_along(sim, record, StaticResult{}, closure, 0.0);
}

// The model is linear until the first bond breaks: solve that part statically and hand over to the explicit run
// at a fraction of the first-break load. An empty `base` is the unloaded specimen.
void PlatenTest::start_along(Simulation& sim, TestRecord& record, const StaticResult& base, const StaticResult& st,
                             double base_stress) const {
  const double H = sim.specimen().height();
  const bool from_rest = base.empty();
  const double first_break = sim.first_break_along(base, st);
  const double base_strain = base.platen_displacement / H;
  const double max_factor = (scene_.loading.max_strain - base_strain) * H / st.platen_displacement;
  axial_stiffness_ = 0.5 * (st.top_force + st.bottom_force) / st.platen_displacement;
  // The start stops at start_stress_limit() too (+inf, which leaves the factor alone, unless a test sets one).
  const double unit_stress = stress_of(0.5 * (st.top_force + st.bottom_force), sim);
  const double limit_factor = (start_stress_limit() - base_stress) / unit_stress;
  const double factor =
      std::min({scene_.numerics.elastic_start_fraction * first_break, 0.5 * max_factor, limit_factor});
  if (!(factor > 0 && std::isfinite(factor))) return;
  const double rate = scene_.loading.transit_strain_fraction > 0.0
                          ? rate_factor(sim, base, st, factor, std::min(0.5 * max_factor, limit_factor))
                          : factor;
  const double v = record.platen_velocity =
      rock_velocity(rate * st.platen_displacement / H, rate * unit_stress, sim);
  if (scene_.loading.transit_strain_fraction > 0.0) sim.find<Platens>()->set_velocity(v);
  const double base_lateral = from_rest ? 0.0 : sim.lateral_strain_of(base), lateral = sim.lateral_strain_of(st);
  const int n = 20;
  for (int k = 1; k <= n; ++k) {
    const double f = factor * double(k) / double(n);
    CurvePoint pt;
    pt.step = -1;
    pt.strain = base_strain + f * st.platen_displacement / H;
    pt.time = f * st.platen_displacement / v;
    pt.stress_top = base_stress + stress_of(f * st.top_force, sim);
    pt.stress_bottom = base_stress + stress_of(f * st.bottom_force, sim);
    pt.lateral_strain = base_lateral + f * lateral;
    record.curve.push_back(pt);
  }
  sim.apply_static(base, st, factor, v);
  record.elastic_start_strain = base_strain + factor * st.platen_displacement / H;
  // Sample the explicit part densely: about curve_points / 5 samples per first-break strain.
  const double per_step = v * record.dt / H;
  const double ramp = record.elastic_start_strain - base_strain;
  record.sample_every = std::max(1L, long(ramp / (0.2 * curve_points_) / per_step));
  Frame f = make_frame(sim, read(sim), "elastic_start");
  f.stress = base_stress + stress_of(0.5 * factor * (st.top_force + st.bottom_force), sim);  // no step computed forces yet
  record.frames.push_back(std::move(f));
  const double interval = scene_.output.frame_strain_interval;
  record.next_frame = (std::floor(record.elastic_start_strain / interval) + 1.0) * interval;
}

// The load factor along `increment` whose strain and stress set the rock's loading rate. A homogeneous rock's start
// ends just below its first break, near the load at which its bonds break in numbers. A heterogeneous rock's start
// ends at its weakest bond's break, which with a Weibull modulus of 1.5 comes at a few hundredths of the peak strain:
// that strain would give a platen tens of times slower than the rock needs. Its rate follows instead the start the
// same rock would reach with every bond at its mean strength (the stated one), but no further than the load at which
// rate_break_share of its own bonds would have broken in the intact linear model: with strong heterogeneity the peak
// comes far below the mean-strength start, once a few per cent of the bonds have broken.
double PlatenTest::rate_factor(const Simulation& sim, const StaticResult& base, const StaticResult& increment,
                               double factor, double cap) const {
  std::vector<double> own = sim.break_factors_along(base, increment, false);
  const std::vector<double> mean = sim.break_factors_along(base, increment, true);
  if (own.empty() || own == mean) return factor;  // no heterogeneity (or no factors in this dimension): its own start
  const double mean_start = scene_.numerics.elastic_start_fraction * *std::min_element(mean.begin(), mean.end());
  const auto k = std::size_t(rate_break_share * double(own.size()));
  std::nth_element(own.begin(), own.begin() + std::ptrdiff_t(k), own.end());
  return std::max(factor, std::min({mean_start, own[k], cap}));
}

double PlatenTest::velocity(const TestRecord& record) const {
  return record.platen_velocity > 0.0 ? record.platen_velocity : scene_.loading.platen_velocity;
}

// With loading.transit_strain_fraction f > 0, the speed at which the platen closes f times the start's strain
// increment eps_s per wave transit of the specimen, H / c with c = sqrt(E_s / rho) from the start's apparent modulus
// E_s = sigma_s / eps_s (the stress increment sigma_s over the strain increment) and the blocks' density (times the
// mass scaling): v = f eps_s c. The inertial part of the platen force is of order rho H (v / T) ~ f sigma_s, so f
// sets the quasi-static error whatever the rock's modulus and strength (docs/model.md, Loading rate).
double PlatenTest::rock_velocity(double strain, double stress, const Simulation&) const {
  const double f = scene_.loading.transit_strain_fraction;
  if (!(f > 0.0)) return scene_.loading.platen_velocity;
  const double rho = scene_.rock.density * scene_.numerics.mass_scaling;
  return f * std::sqrt(std::max(strain * stress, 0.0) / rho);
}

double PlatenTest::axial_stiffness(const Simulation& sim) {
  if (!axial_stiffness_) {
    const StaticResult st = closure_solve(sim);
    axial_stiffness_ = 0.5 * (st.top_force + st.bottom_force) / st.platen_displacement;
  }
  return *axial_stiffness_;
}

bool PlatenTest::stop(const Simulation& sim, const Reading& reading, const TestRecord& record,
                      std::string& reason) const {
  const double floor = stress_floor();
  if (sim.cracks().empty() || sim.steps() <= record.peak_step) return false;
  const bool dropped = reading.stress - floor < scene_.loading.stop_fraction * (record.peak - floor);
  const bool residual = reading.strain > (1.0 + scene_.loading.post_peak_strain) * record.at_peak.strain;
  if (!dropped && !residual) return false;
  reason = dropped ? "post_peak" : "post_peak_strain";
  return true;
}

void ConfinedPlatenTest::install(Simulation& sim) {
  PlatenTest::install(sim);
  sim.add_jacket(0.0);  // the pressure comes with start(), after the static solves at rest
}

// The static solves do not depend on the jacket's pressure at rest (the pressure's load is an input of each).
void ConfinedPlatenTest::prepare(const Simulation& sim, const std::atomic<int>& threads) {
  if (!(pressure() > 0.0)) {
    PlatenTest::prepare(sim, threads);
    return;
  }
  prepared_isotropic_ = isotropic_state(sim, pressure(), &threads);
  prepared_closure_ = closure_solve(sim, &threads);
}

void ConfinedPlatenTest::start(Simulation& sim, TestRecord& record) {
  const double p = pressure();
  sim.find<Jacket>()->set_pressure(p);
  record.platen_velocity = scene_.loading.platen_velocity;  // start_along sets the rock's speed where asked
  if (!(p > 0.0)) {
    PlatenTest::start(sim, record);
    return;
  }
  const double H = sim.specimen().height(), v = velocity(record);
  const StaticResult iso = prepared_isotropic_ ? std::move(*prepared_isotropic_) : isotropic_state(sim, p);
  prepared_isotropic_.reset();
  record.preload_strain = iso.platen_displacement / H;
  const double iso_lateral = sim.lateral_strain_of(iso);
  const int n = 10;  // the isotropic stage on the curve (static: no time passes)
  for (int k = 1; k <= n; ++k) {
    const double f = double(k) / double(n);
    CurvePoint pt;
    pt.step = -1;
    pt.strain = f * record.preload_strain;
    pt.stress_top = pt.stress_bottom = f * p;
    pt.lateral_strain = f * iso_lateral;
    record.curve.push_back(pt);
  }
  const StaticResult axial = prepared_closure_ ? std::move(*prepared_closure_) : closure_solve(sim);
  prepared_closure_.reset();
  if (scene_.numerics.elastic_start) {
    start_along(sim, record, iso, axial, p);
  } else {
    sim.apply_static(iso, axial, 0.0, v);
    record.elastic_start_strain = record.preload_strain;
    axial_stiffness_ = 0.5 * (axial.top_force + axial.bottom_force) / axial.platen_displacement;
  }
}

StaticResult isotropic_state(const Simulation& sim, double p, const std::atomic<int>* threads) {
  const double target = p * sim.specimen().width() * sim.specimen().thickness;  // N: the platen force of sigma_1 = p
  StaticOptions with_pressure;
  with_pressure.platen_displacement = 0.0;
  with_pressure.load = sim.pressure_load(p);
  with_pressure.threads = threads;
  StaticOptions closure;
  closure.threads = threads;
  closure.platen_displacement = 1e-6 * sim.specimen().height();
  const StaticResult a = sim.solve_static(with_pressure);  // the pressure between fixed platens
  const StaticResult b = sim.solve_static(closure);        // a platen closure alone
  // sigma_1 = p: s closures on top of the pressure. Superposition holds while the linear parts' states agree; a
  // combined solve checks it and corrects s (secant on the platen force) until the force is p times the area.
  double s = (target - a.top_force) / b.top_force;
  StaticResult state = superpose(a, 1.0, b, s);
  for (int it = 0; it < 10; ++it) {
    StaticOptions both = with_pressure;
    both.platen_displacement = s * closure.platen_displacement;
    state = sim.solve_static(both);
    const double miss = target - state.top_force;
    if (std::abs(miss) <= 1e-10 * target) break;
    s += miss / b.top_force;
  }
  return state;
}

}  // namespace rbdem
