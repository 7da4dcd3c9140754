// DEM verification cases: objectivity, the parallel bond's moment stiffness, a bonded pair's frequency, energy
// in a frictionless impact, and the static elastic solve against the explicit run (docs/theory.md, sections 5, 8, 9).
#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "compare/verify/dem_measures.hpp"
#include "compare/verify/specimens.hpp"
#include "compare/verify/verify.hpp"
#include "dem/boundary/components.hpp"
#include "dem/engine.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/static_solve.hpp"
#include "dem/driver/driver.hpp"
#include "dem/topology.hpp"

namespace rbdem::verify {

namespace {

// Free blocks: an engine with no boundary components attached, on one thread.
EngineOptions free_blocks(const Scene& s) {
  EngineOptions o = EngineOptions::from_scene(s);
  o.threads = 1;
  return o;
}

CaseResult objectivity(const Context&) {
  CaseResult r;
  r.checks = "a rigid translation (0.3 m, -0.2 m) and rotation (1 rad) of the bonded specimen create no bond force";
  r.reference = "objectivity of the co-rotated bond kinematics (docs/theory.md, sections 5, 9): zero force";
  r.unit = "strain";
  const RigidMotionMeasure m = rigid_motion_forces();
  r.measured = m.spurious_strain, r.reference_value = 0, r.error = m.spurious_strain;
  r.error_definition = "max over bonds of |force| / (E* L t): the spurious strain";
  r.tolerance = 1e-12;
  r.tolerance_source = "round-off: positions of 0.3 m carry 1e-16 relative error, 3e-14 of a 1 mm bond";
  r.cost = fmt::format("{} blocks, {} bonds, one step", m.blocks, m.bonds);
  return r;
}

// The parallel bond's moment for a relative rotation dtheta: M = -(E* / d) (L t) (L^2 / 12) dtheta.
CaseResult bond_moment(const Context&) {
  CaseResult r;
  r.checks = "the parallel bond's moment under a small relative rotation of two bonded blocks";
  r.reference = "M = -kb_n I dtheta, kb_n = E*/d, I = t L^3 / 12 (docs/theory.md, section 5)";
  r.unit = "N m";
  const Scene scene = elastic_scene();
  const double a = 1e-3, b = 0.8e-3, t = 1.0, dth = 1e-7;
  const Topology<2> topo = build_topology(rhombus(a, b), t, 2700.0);
  Engine<2> e(topo, scene, free_blocks(scene));
  e.edit([&](ModelState<2>& s) { s.theta[1] = dth; });
  const double L = 2 * a, d = 2 * b / 3;
  r.reference_value = -(scene.rock.effective_modulus / d) * t * L * L * L / 12.0 * dth;
  r.measured = e.bond_forces(0).m_b;
  r.error = std::abs(r.measured / r.reference_value - 1.0);
  r.error_definition = "|M / M_ref - 1|";
  r.tolerance = 1e-9;
  r.tolerance_source = "round-off (the moment is linear in the rotation)";
  r.cost = "2 blocks, 1 bond";
  return r;
}

CaseResult pair_frequency(const Context&) {
  CaseResult r;
  r.checks = "the period of a bonded block oscillating against a fixed one (bond and closed linear part in parallel)";
  r.reference = "T = 2 pi sqrt(m / k), k = 2 E* L t / d (parallel bond + linear part, docs/theory.md, sections 5, 7)";
  r.unit = "s";
  const double steps_per_period = 200;
  const PairPeriodMeasure m = bonded_pair_period(steps_per_period);
  r.measured = m.period, r.reference_value = m.expected;
  r.error = std::abs(m.period / m.expected - 1.0);
  r.error_definition = "|T / T_ref - 1|, T from 10 upward zero crossings";
  // Central difference lengthens the period by (omega dt)^2 / 24 to leading order.
  const double wdt = 2 * std::numbers::pi / steps_per_period;
  r.tolerance = 2.0 * wdt * wdt / 24.0;
  r.tolerance_source = fmt::format("twice the central difference's period error (omega dt)^2 / 24 = {:.2e} at "
                                   "{:g} steps per period",
                                   wdt * wdt / 24.0, steps_per_period);
  r.cost = fmt::format("2 blocks, {} steps", m.steps);
  return r;
}

CaseResult impact_energy(const Context&) {
  CaseResult r;
  r.checks = "kinetic energy after a frictionless elastic impact of two blocks (head on and oblique at 20 deg)";
  r.reference = "energy conservation (docs/theory.md, section 9): KE_after = KE_before";
  r.unit = "-";
  double worst = 0;
  long steps = 0;
  for (double angle_deg : {0.0, 20.0}) {
    const ImpactMeasure m = frictionless_impact(angle_deg);
    if (!m.touched || !m.separated) throw std::runtime_error("the blocks did not meet and separate");
    r.table.push_back({{"impact_angle_deg", angle_deg}, {"energy_ratio", m.energy_ratio}, {"steps", m.steps}});
    if (std::abs(m.energy_ratio - 1.0) >= worst) worst = std::abs(m.energy_ratio - 1.0), r.measured = m.energy_ratio;
    steps += m.steps;
  }
  r.reference_value = 1.0;
  r.error = worst;
  r.error_definition = "max |KE_after / KE_before - 1| over both impacts";
  // The contact force switches on and off within a step: one step of the contact's mean work out of about 100
  // steps of contact (dt = 0.02 sqrt(m / k)) bounds the error at about 1 %; the symplectic part adds (omega dt)^2.
  r.tolerance = 0.01;
  r.tolerance_source = "contact entry and exit within one step: about 1 / (steps in contact) = 1 % at dt = 0.02 "
                       "sqrt(m / k)";
  r.cost = fmt::format("2 blocks, {} steps", steps);
  return r;
}

CaseResult softening_energy(const Context&) {
  CaseResult r;
  r.checks = "energy a softening bond dissipates until it breaks, per unit area, pulled open on two block sizes";
  r.reference = "G_f (docs/model.md, \"Softening bonds\"): the fracture energy, whatever the block size";
  r.unit = "J/m^2";
  const double gf = 0.5;
  double worst = -1;
  long steps = 0;
  for (const double a : {0.5e-3, 1e-3}) {
    const SofteningPullMeasure m = softening_pull(a, gf, false);
    if (!m.broke) throw std::runtime_error("the softening bond did not break");
    r.table.push_back({{"edge_half_length_m", a}, {"energy_per_area", m.energy_per_area},
                       {"peak_stress_pa", m.peak_stress}, {"break_opening_m", m.break_opening}});
    const double err = std::abs(m.energy_per_area / gf - 1.0);
    if (err > worst) worst = err, r.measured = m.energy_per_area;
    steps += m.steps;
  }
  r.reference_value = gf;
  r.error = worst;
  r.error_definition = "max |energy / G_f - 1| over both block sizes";
  // Trapezoidal integration over 1/200 of the elastic limit per step, with the break inside the last step.
  r.tolerance = 0.01;
  r.tolerance_source = "trapezoidal rule over steps of 1/200 of the elastic opening, the break within one step";
  r.cost = fmt::format("2 blocks, {} steps", steps);
  return r;
}

// Least-squares slope of stress over strain for the curve points with strain >= from.
double slope(const std::vector<CurvePoint>& curve, double from) {
  std::vector<double> x, y;
  for (const auto& p : curve)
    if (p.strain >= from) x.push_back(p.strain), y.push_back(p.stress());
  return least_squares_slope(x, y);
}

CaseResult static_vs_explicit(const Context& ctx) {
  CaseResult r;
  r.checks = "the static elastic solve's apparent modulus against the slope of an explicit run from rest";
  r.reference = "the explicit central-difference run of the same mesh (slope over 30-100 % of 2e-4 strain)";
  r.unit = "Pa";
  double worst = -1;
  std::size_t blocks = 0;
  long steps = 0;
  for (const double beta : ctx.quick ? std::vector<double>{0.0} : std::vector<double>{0.0, 60.0}) {
    const SlopeMeasure m = static_and_explicit_moduli(beta, false);
    const double E = m.static_state.apparent_modulus, err = std::abs(E / m.explicit_modulus - 1.0);
    r.table.push_back({{"beta_deg", beta}, {"static_pa", E}, {"explicit_pa", m.explicit_modulus}, {"error", err},
                       {"steps", m.steps}});
    if (err > worst) worst = err, r.measured = E, r.reference_value = m.explicit_modulus;
    blocks = m.blocks;
    steps += m.steps;
  }
  r.error = worst;
  r.error_definition = "max |E_static / E_explicit - 1| over the dips";
  r.tolerance = 0.02;
  r.tolerance_source = "the explicit run's dynamic overshoot at 0.01 m/s: platen force mismatch 1.6-3 % in the "
                       "loading-rate study (docs/performance.md)";
  r.cost = fmt::format("mesh 4 mm, {} blocks, {} explicit steps", blocks, steps);
  return r;
}

}  // namespace

RigidMotionMeasure rigid_motion_forces() {
  const Scene scene = elastic_scene();
  SpecimenGeometry g;
  const Topology<2> topo = build_topology(mesh_specimen(g, 0.005), 1.0, 2700.0);
  Engine<2> e(topo, scene, free_blocks(scene));
  const double q = 1.0, c = std::cos(q), s = std::sin(q), tx = 0.3, ty = -0.2;
  e.edit([&](ModelState<2>& st) {
    for (std::size_t b = 0; b < st.num_blocks(); ++b) {
      const double x = st.x[b], y = st.y[b];
      st.x[b] = tx + c * x - s * y;
      st.y[b] = ty + s * x + c * y;
      st.theta[b] = q;
    }
  });
  e.set_dt(1e-12);
  e.step();
  RigidMotionMeasure m;
  for (std::size_t b = 0; b < e.model().num_bonds(); ++b) {
    const BondForces f = e.bond_forces(int(b));
    const double L = e.model().frame.L[b], scale = scene.rock.effective_modulus * L * topo.thickness;
    const double worst = std::max({std::abs(f.fn_b), std::abs(f.fs_b), std::abs(f.m_b) / L, std::abs(f.fn_lin)});
    m.max_force = std::max({m.max_force, worst, std::abs(f.m_b)});
    m.spurious_strain = std::max(m.spurious_strain, worst / scale);
  }
  m.blocks = e.model().num_blocks(), m.bonds = e.model().num_bonds(), m.cracks = e.cracks().size();
  return m;
}

PairPeriodMeasure bonded_pair_period(double steps_per_period) {
  const Scene scene = elastic_scene();
  const double a = 1e-3, b = 0.8e-3, t = 1.0;
  const Topology<2> topo = build_topology(rhombus(a, b), t, 2700.0);
  Engine<2> e(topo, scene, free_blocks(scene));
  e.fix_block(0);
  const double k = 2.0 * scene.rock.effective_modulus * (2 * a) * t / (2 * b / 3);
  const double mass = 2700.0 * t * a * b;  // triangle of base 2a and height b
  const double preload = 1e3;              // N
  BlockGroupImpl<2> load(e, {"preload", {1}, GroupSettings::Mode::force, {0.0, -preload, 0.0}});
  e.attach(&load);
  const double y_eq = e.state().y[1] - preload / k;
  e.edit([&](ModelState<2>& s) { s.y[1] = y_eq + 0.3 * preload / k; });  // amplitude 30 % of the preload: stays closed
  PairPeriodMeasure m;
  m.expected = 2 * std::numbers::pi * std::sqrt(mass / k);
  e.set_dt(m.expected / steps_per_period);
  std::vector<double> crossings;
  double prev = e.state().y[1] - y_eq;
  while (crossings.size() < 11 && e.time() < 20 * m.expected) {
    e.step();
    const double now = e.state().y[1] - y_eq;
    if (prev < 0 && now >= 0) crossings.push_back(e.time() - e.dt() * now / (now - prev));
    prev = now;
  }
  if (crossings.size() < 11) throw std::runtime_error("the pair did not oscillate");
  m.period = (crossings.back() - crossings.front()) / 10.0;
  m.max_sideways = std::abs(e.state().x[1]);
  m.steps = e.steps();
  return m;
}

ImpactMeasure frictionless_impact(double angle_deg) {
  Scene scene = elastic_scene();
  scene.rock.contact_friction = scene.joint.contact_friction = 0.0;
  const double a = 1e-3;
  const Topology<2> topo = build_topology(facing_triangles(a), 1.0, 2700.0);
  Engine<2> e(topo, scene, free_blocks(scene));
  const double v = 1.0, q = angle_deg * std::numbers::pi / 180;
  e.edit([&](ModelState<2>& s) {
    s.vx[0] = v * std::cos(q), s.vy[0] = -v * std::sin(q);
    s.vx[1] = -v * std::cos(q);
  });
  const Model<2>& M = e.model();
  const double k = scene.rock.effective_modulus / (M.inradius[0] + M.inradius[1]) * a * std::sqrt(2.0);
  e.set_dt(0.02 * std::sqrt(M.mass[0] / k));
  const double e0 = e.energies().kinetic;
  ImpactMeasure m;
  for (int s = 0; s < 200000; ++s) {
    e.step();
    if (e.active_contacts() > 0) m.touched = true;
    if (m.touched && e.active_contacts() == 0) break;
  }
  m.separated = m.touched && e.active_contacts() == 0;
  m.energy_ratio = e.energies().kinetic / e0;
  m.steps = e.steps();
  return m;
}

SofteningPullMeasure softening_pull(double a, double fracture_energy, bool shear) {
  Scene scene = elastic_scene();
  scene.rock.effective_modulus = 160e9, scene.rock.stiffness_ratio = 1.5;
  scene.rock.tensile_strength = 7.5e6, scene.rock.cohesion = 7.5e6, scene.rock.friction_deg = 40.0;
  scene.rock.fracture_energy = fracture_energy;
  const Topology<2> topo = build_topology(rhombus(a, 0.8 * a), 1.0, 2700.0);
  Engine<2> e(topo, scene, free_blocks(scene));
  e.fix_block(0), e.fix_block(1);
  e.set_dt(1e-12);
  const BondFrames& f = e.model().frame;
  const double ux = shear ? -f.n0y[0] : f.n0x[0], uy = shear ? f.n0x[0] : f.n0y[0];  // normal or tangent
  const double A = f.L[0] * 1.0;
  const std::size_t j = std::size_t(e.model().bj[0]);
  // Elastic limit of the displacement: sigma_c d / E* (normal) or c kappa d / E* (shear).
  const double limit = (shear ? 7.5e6 * 1.5 : 7.5e6) * topo.bonds.d[0] / scene.rock.effective_modulus;
  const double step = limit / 200.0;
  SofteningPullMeasure m;
  double previous = 0, moved = 0;
  for (int k = 0; k < 400000 && !m.broke; ++k) {
    e.edit([&](ModelState<2>& s) { s.x[j] += step * ux, s.y[j] += step * uy; });
    moved += step;
    e.step();
    m.broke = e.state().broken[0] != 0;
    const BondForces bf = e.bond_forces(0);
    const double force = shear ? std::abs(bf.fs_b) : -bf.fn_b;  // resisting force, positive
    m.energy_per_area += 0.5 * (previous + force) * step / A;
    m.peak_stress = std::max(m.peak_stress, force / A);
    previous = force;
    if (m.broke) m.break_opening = moved;
  }
  m.steps = e.steps();
  return m;
}

SlopeMeasure static_and_explicit_moduli(double beta_deg, bool slip_when_bonded) {
  Scene scene = elastic_scene();
  scene.numerics.damping = Scene{}.numerics.damping;
  scene.numerics.threads = 1;
  scene.rock.slip_when_bonded = scene.joint.slip_when_bonded = slip_when_bonded;
  scene.mesh.size = 0.004;
  scene.joint_set.dip_deg = beta_deg;
  scene.numerics.elastic_start = false;
  scene.loading.max_strain = 2e-4;
  const TriMesh mesh = make_mesh(scene);
  const auto sim = Simulation::create(scene, mesh);
  sim->add_platens({scene.loading.platen_velocity, scene.loading.platen_friction});
  SlopeMeasure m;
  m.static_state = sim->solve_static();
  const TestResult run = run_test("ucs", scene, mesh);
  m.explicit_modulus = slope(run.curve, 0.3 * scene.loading.max_strain);
  m.curve_points = run.curve.size(), m.cracks = run.cracks.size(), m.blocks = sim->num_blocks();
  m.steps = run.steps;
  return m;
}

std::vector<CaseSpec> dem_cases() {
  return {make_case("dem.objectivity", true, objectivity), make_case("dem.bond_moment_stiffness", true, bond_moment),
          make_case("dem.pair_frequency", true, pair_frequency), make_case("dem.impact_energy", true, impact_energy),
          make_case("dem.static_vs_explicit", true, static_vs_explicit),
          make_case("dem.softening_energy", true, softening_energy)};
}

}  // namespace rbdem::verify
