// The 3D cases: the face bond's objectivity under a finite rigid motion, the torque-free asymmetric block's
// angular momentum and energy, the FE twin on tetrahedra against Amadei's 3D apparent modulus and lateral strains,
// the 3D elastic gate on the paper's cylinder and its confined slope at 60 deg against Jaeger's (docs/theory.md,
// "The face bond in 3D", "Rigid-block dynamics", "The layered cylinder in 3D"; docs/elastic.md, "Three
// dimensions").
#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "compare/gate/elastic_gate3.hpp"
#include "compare/verify/confined.hpp"
#include "compare/verify/dem_measures.hpp"
#include "compare/verify/verify.hpp"
#include "dem/geometry3.hpp"
#include "dem/rigid3.hpp"
#include "dem/scene.hpp"
#include "dem/specimen_mesh3.hpp"
#include "dem/stages/face_bond_kernel.hpp"
#include "theory/elasticity3.hpp"

#ifdef RBDEM_HAVE_CONTINUUM
#include "continuum/fe_3d.hpp"
#endif

namespace rbdem::verify {

namespace {

constexpr double mm = 1e-3;
constexpr double dips[] = {0, 15, 30, 45, 60, 75, 90};

// Two tetrahedra of about a millimetre sharing an oblique, scalene face; the law of the paper's rock.
struct BondedPair {
  Tri face{{{0.0, 0.0, 0.0}, {1.1 * mm, 0.2 * mm, 0.1 * mm}, {0.3 * mm, 0.9 * mm, -0.05 * mm}}};
  Vec3 apex_i{0.4 * mm, 0.3 * mm, -0.8 * mm}, apex_j{0.5 * mm, 0.4 * mm, 0.9 * mm};
  Vec3 ci() const { return 0.25 * (((face[0] + face[1]) + face[2]) + apex_i); }
  Vec3 cj() const { return 0.25 * (((face[0] + face[1]) + face[2]) + apex_j); }
};

stages::BlockKin3 moved(const stages::BlockKin3& b, Quat r, Vec3 t) {
  return {rotate(r, b.x) + t, r * b.q, rotate(r, b.v), rotate(r, b.omega)};
}

CaseResult objectivity3(const Context&) {
  CaseResult r;
  r.checks = "a bonded pair of tetrahedra moved by a finite rigid motion (30 deg about an oblique axis, 0.8 mm): no "
             "force; a strained pair moved the same way: the same face-frame forces, the world forces turned";
  r.reference = "objectivity of the face bond's kinematics (docs/theory.md, \"The face bond in 3D\"): zero force, "
                "and forces that turn with the pair";
  r.unit = "relative";
  const BondedPair p;
  const Scene scene;
  const FaceBond law{1.0 / scene.rock.stiffness_ratio,
                     {scene.rock.tensile_strength, scene.rock.cohesion,
                      std::tan(scene.rock.friction_deg * std::numbers::pi / 180.0), scene.rock.moment_factor},
                     0.0};
  const stages::FaceBondFrame b =
      stages::face_bond_frame(p.ci(), p.cj(), p.face, law, scene.rock.effective_modulus, scene.rock.contact_friction);
  const Quat rot = from_rotation_vector((std::numbers::pi / 6.0 / std::sqrt(14.0)) * Vec3{1, 2, 3});
  const Vec3 t{0.3 * mm, -0.2 * mm, 0.7 * mm};
  const stages::BlockKin3 I0{p.ci(), {}, {}, {}}, J0{p.cj(), {}, {}, {}};
  const double F = b.k.kn * b.section.r_max, M = F * b.section.r_max;  // the force and moment scales
  const auto rigid = stages::eval_face_bond(b, moved(I0, rot, t), moved(J0, rot, t), 0.0, 0, 0, 1.0);
  const double spurious = std::max({norm(rigid.f) / F, norm(rigid.mi) / M, norm(rigid.mj) / M});
  // Strained: closing, slip, bending and twist (the linear part partly closed), then the same rigid motion.
  const stages::BlockKin3 J1{p.cj() + Vec3{1e-7, -2e-7, -3e-7}, from_rotation_vector({1.5e-3, -2e-3, 5e-4}), {}, {}};
  const auto before = stages::eval_face_bond(b, I0, J1, 0.0, 0, 0, 1.0);
  const auto after = stages::eval_face_bond(b, moved(I0, rot, t), moved(J1, rot, t), 0.0, 0, 0, 1.0);
  const double turned = std::max({norm(after.f - rotate(rot, before.f)) / F,
                                  norm(after.mi - rotate(rot, before.mi)) / M,
                                  norm(after.mj - rotate(rot, before.mj)) / M});
  r.table.push_back({{"motion", "rigid, unstrained"}, {"error", spurious}});
  r.table.push_back({{"motion", "strained, then moved"}, {"error", turned}, {"force_n", norm(before.f)}});
  r.measured = std::max(spurious, turned), r.reference_value = 0, r.error = r.measured;
  r.error_definition = "max of |force| / (K_n r_max) and |moment| / (K_n r_max^2) of the rigid motion, and of the "
                       "strained pair's force and moments against the unmoved ones turned";
  r.tolerance = 1e-12;
  r.tolerance_source = "round-off: coordinates of a millimetre carry 1e-19 m, what a strained bond's gap resolves";
  r.cost = "2 tetrahedra, 1 face bond, 3 evaluations";
  return r;
}

}  // namespace

TorqueFreeMeasure torque_free_run(Vec3 omega_body, double dt, long steps) {
  const RigidBody3 body{1.0, {1.0, 2.0, 3.0}, from_rotation_vector({0.3, -0.5, 0.8})};
  RigidState3 s;
  s.omega = rotate(body.axes, omega_body);
  const double e0 = kinetic_energy(body, s);
  const Vec3 L0 = angular_momentum(body, s);
  TorqueFreeMeasure out;
  double lo = e0, hi = e0;
  for (long n = 0; n < steps; ++n) {
    rigid_step(body, s, {}, {}, dt, 0.0);
    const double e = kinetic_energy(body, s);
    lo = std::min(lo, e), hi = std::max(hi, e);
    out.momentum_drift = std::max(out.momentum_drift, norm(angular_momentum(body, s) - L0) / norm(L0));
    out.unit_error = std::max(out.unit_error, std::abs(norm(s.q) - 1.0));
  }
  out.energy_spread = (hi - lo) / e0;
  out.energy_drift = std::abs(kinetic_energy(body, s) - e0) / e0;
  return out;
}

namespace {

// The torque-free block near its unstable intermediate axis at about 1 rad/s.
const Vec3 intermediate_axis_spin{0.01, 1.0, 0.01};

CaseResult torque_free_momentum(const Context&) {
  CaseResult r;
  r.checks = "a torque-free asymmetric block tumbling about its unstable intermediate axis, 1e5 steps (about 160 "
             "turns): the angular momentum kept";
  r.reference = "Euler's equations: L is a constant (docs/theory.md, section 11.7, \"Rigid-block dynamics\")";
  r.unit = "relative";
  const long steps = 100000;
  const TorqueFreeMeasure a = torque_free_run(intermediate_axis_spin, 0.01, steps);
  r.table.push_back({{"dt_s", 0.01}, {"steps", steps}, {"momentum_drift", a.momentum_drift}});
  r.measured = a.momentum_drift, r.reference_value = 0, r.error = a.momentum_drift;
  r.error_definition = "max over the steps of |L - L0| / |L0|";
  r.tolerance = 1e-15 * double(steps);
  r.tolerance_source = "round-off: each sub-rotation keeps L; turning omega into L and back adds about 1e-16 a step";
  r.cost = fmt::format("1 block, {} steps", steps);
  return r;
}

CaseResult torque_free_energy(const Context&) {
  CaseResult r;
  r.checks = "the same block's kinetic energy at dt = 0.01 s and dt / 2: it oscillates by O(dt^2) and does not drift";
  r.reference = "Euler's equations: the energy is a constant; the scheme's error is second order in dt";
  r.unit = "order";
  const double dt = 0.01;
  const long steps = 100000;
  const TorqueFreeMeasure a = torque_free_run(intermediate_axis_spin, dt, steps),
                          h = torque_free_run(intermediate_axis_spin, 0.5 * dt, 2 * steps);
  r.table.push_back({{"dt_s", dt}, {"steps", steps}, {"energy_spread", a.energy_spread},
                     {"energy_drift", a.energy_drift}});
  r.table.push_back({{"dt_s", 0.5 * dt}, {"steps", 2 * steps}, {"energy_spread", h.energy_spread},
                     {"energy_drift", h.energy_drift}});
  r.measured = std::log2(a.energy_spread / h.energy_spread), r.reference_value = 2.0;
  r.error = std::abs(r.measured - r.reference_value);
  // A drift beyond the band the energy oscillates in is a failure of its own.
  if (a.energy_drift > a.energy_spread || h.energy_drift > h.energy_spread) r.error = std::nan("");
  r.error_definition = "|observed order - 2|, the order log2 of the ratio of the energy's spreads at dt and dt / 2 "
                       "(NaN, a failure, when the final energy lies outside its band: a drift)";
  r.tolerance = 0.32;
  r.tolerance_source = "the spreads' ratio within 3.2 to 5 (4 at second order): two runs of 160 turns sample the "
                       "oscillation's extremes at different phases";
  r.cost = fmt::format("1 block, {} + {} steps", steps, 2 * steps);
  return r;
}

#ifdef RBDEM_HAVE_CONTINUUM
CaseResult fe_amadei3(const Context& ctx) {
  CaseResult r;
  r.checks = "the 3D FE twin (P1 tetrahedra, frictionless platens) on the jointed 4 mm cylinder at seven dips: the "
             "platens' modulus, the mean-strain modulus and both apparent Poisson's ratios";
  r.reference = "Amadei's 3D apparent modulus 1 / S'_33 and lateral strains of the rotated compliance "
                "(theory/elasticity3.hpp; docs/theory.md, \"The layered cylinder in 3D\")";
  r.unit = "Pa";
  const theory::TIConstants c{60e9, 0.2, 25e9, 0.12, 9e9};  // clearly anisotropic: E / E' = 2.4
  SpecimenGeometry3 g;
  g.set1 = {60.0, 0.0, 0.025, 0.0};
  if (ctx.log) ctx.log("  meshing the 4 mm cylinder");
  const TetMesh mesh = mesh_specimen3(g, 0.004);
  double worst = 0, worst_platen = 0;
  std::size_t dofs = 0;
  for (double dip : dips) {
    const continuum::Fe3Result fe = continuum::solve_elastic_3d(mesh, c, dip, 0.0);
    const theory::Uniaxial3 a = theory::amadei_uniaxial_3d(c, dip);
    const double platen = std::abs(fe.apparent_modulus / a.modulus - 1);
    const double mean = std::abs(fe.mean_strain_modulus / a.modulus - 1);
    const double nu =
        std::max(std::abs(fe.poisson_strike - a.poisson_strike), std::abs(fe.poisson_dip - a.poisson_dip));
    r.table.push_back({{"beta_deg", dip}, {"amadei_pa", a.modulus}, {"fe_platen_pa", fe.apparent_modulus},
                       {"platen_error", platen}, {"mean_strain_error", mean}, {"poisson_error", nu}});
    if (std::max({platen, mean, nu}) >= worst) {
      worst = std::max({platen, mean, nu});
      r.measured = fe.apparent_modulus, r.reference_value = a.modulus;
    }
    worst_platen = std::max(worst_platen, platen);
    dofs = fe.dofs;
  }
  r.error = worst;
  r.error_definition = "max over the dips of |E_platens / E_Amadei - 1|, |E_mean / E_Amadei - 1| and |nu - nu_Amadei|";
  r.tolerance = 1e-6;
  r.tolerance_source = "the faceting of the cylinder's side at 4 mm (at most 5e-7 in the platens' modulus); the mean "
                       "strain and the lateral strains are exact up to the CG tolerance (1e-10 relative residual)";
  r.cost = fmt::format("{} tetrahedra, {} DoFs, 7 solves", mesh.tets.size(), dofs);
  return r;
}

// The gate every 3D failure run can apply (`rbdem elastic` on a 3D scene) on the paper's rock as a cylinder at
// 4 mm: constants from three prisms, then the cylinder at seven dips.
CaseResult gate3(const Context& ctx) {
  CaseResult r;
  r.checks = "the 3D elastic gate on the paper scene's cylinder (4 mm tetrahedra, joints every 10 mm): the DEM's "
             "static moduli at seven dips against the FE twin on the same tetrahedra with the DEM's own five "
             "constants";
  r.reference = "continuum::solve_elastic_3d with the constants from the DEM's virtual tests on prisms; Amadei with "
                "them beside it (compare/gate/elastic_gate3.hpp)";
  r.unit = "Pa";
  Scene scene;
  apply_override(scene, "specimen.dimension=3");
  apply_override(scene, "mesh.size=0.004");
  validate(scene);
  compare::Elastic3Options o;
  o.log = ctx.log;
  const compare::Elastic3Report rep = compare::run_elastic_gate3(scene, o);
  for (const auto& a : rep.angles) {
    r.table.push_back({{"beta_deg", a.beta_deg}, {"dem_static_pa", a.dem_static}, {"fe_pa", a.fe},
                       {"amadei_pa", a.amadei}, {"deviation", a.deviation_fe()}, {"blocks", a.blocks}});
    if (a.beta_deg == rep.gate.worst_beta_deg) r.measured = a.dem_static, r.reference_value = a.fe;
  }
  r.error = rep.gate.max_deviation;
  r.error_definition = "max over dips |E_DEM,static / E_FE - 1|";
  r.tolerance = scene.elastic.tolerance;
  r.tolerance_source = "elastic.tolerance, the 3D gate's (docs/elastic.md, \"Three dimensions\": 1.8 % at 4 mm, "
                       "3.1 % at 3 mm, 12 % at 8 mm)";
  r.cost = fmt::format("mesh 4 mm, {}-{} blocks per dip, 4 prisms + 7 dips of static solves and FE twins",
                       std::min_element(rep.angles.begin(), rep.angles.end(),
                                        [](auto& x, auto& y) { return x.blocks < y.blocks; })->blocks,
                       std::max_element(rep.angles.begin(), rep.angles.end(),
                                        [](auto& x, auto& y) { return x.blocks < y.blocks; })->blocks);
  return r;
}
#endif

// Confined compression of the calibrated cylinder at 60 deg, sigma_3 = 0 and 10 MPa (one 8 mm mesh): the slope
// against Jaeger's, as strength.triaxial_slope does in 2D.
CaseResult triaxial_slope3(const Context& ctx) {
  CaseResult r;
  r.checks = "the slope d sigma_1 / d sigma_3 of the calibrated cylinder (scenes/cylinder.toml, 8 mm) in confined "
             "compression at beta = 60 deg (sliding on the joints) between sigma_3 = 0 and 10 MPa";
  r.reference = "Jaeger under confinement: 1 + 2 mu / ((1 - mu cot beta) sin 2 beta), mu of the bonded joint's "
                "envelope (docs/theory.md, section 4)";
  r.unit = "-";
  study::StudySpec spec = confined_spec(cylinder_scene(), "verify_confined3");
  spec.dips = {60};
  const std::filesystem::path out = ctx.out / "confined3";
  std::filesystem::create_directories(out);
  if (ctx.log) ctx.log("verify: running the cylinder confined at 0 and 10 MPa, 60 deg, into " + out.string());
  const auto t0 = std::chrono::steady_clock::now();
  const auto results = study::run_cases(study::expand(spec), out, study::SweepOptions{});
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  long steps = 0;
  for (const auto& c : results) {
    steps += c.summary["steps"].get<long>();
    r.table.push_back({{"sigma3_pa", c.c.scene.loading.confining_pressure},
                       {"peak_stress_pa", c.summary["peak_stress_pa"]}, {"failure_mode", c.summary["failure_mode"]},
                       {"steps", c.summary["steps"]}});
  }
  for (const auto& e : study::write_envelopes(results, out))
    if (e.beta_deg == 60.0) r.measured = e.slope_0_10, r.reference_value = e.jaeger_slope;
  r.error = std::abs(r.measured / r.reference_value - 1.0);
  r.error_definition = "|k_DEM / k_Jaeger - 1|";
  r.tolerance = 0.15;
  r.tolerance_source = "as strength.triaxial_slope in 2D: the joints fail by their bonds, progressively, before the "
                       "whole plane reaches the envelope (the uniaxial strength at 60 deg is 45 % below Jaeger's on "
                       "this mesh); one mesh (docs/studies.md, \"The cylinder\": 10 % below on it)";
  r.cost = fmt::format("2 runs of the 8 mm cylinder, {} steps, {:.0f} s", steps, seconds);
  return r;
}

}  // namespace

Scene cylinder_scene() {
  Scene s;
  for (const char* key : {"specimen.dimension=3", "mesh.size=0.008", "rock.tensile_strength=14783000",
                          "rock.cohesion=14783000", "joint.tensile_strength=5251000", "joint.cohesion=5251000",
                          "joint.contact_friction=0.5774"})
    apply_override(s, key);
  validate(s);
  return s;
}

std::vector<CaseSpec> dim3_cases() {
  std::vector<CaseSpec> out{make_case("dem3.objectivity", true, objectivity3),
                            make_case("dem3.torque_free_momentum", true, torque_free_momentum),
                            make_case("dem3.torque_free_energy", true, torque_free_energy)};
#ifdef RBDEM_HAVE_CONTINUUM
  out.push_back(make_case("fe3.amadei_seven_dips", true, fe_amadei3));
  out.push_back(make_case("dem_fe3.elastic_gate", false, gate3));
#endif
  out.push_back(make_case("strength3.triaxial_slope", false, triaxial_slope3));
  return out;
}

}  // namespace rbdem::verify
