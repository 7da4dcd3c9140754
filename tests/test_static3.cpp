// The static elastic solve of the 3D face-bond network (dem/static3.hpp) against finite differences of the face
// bond's kernel, Clapeyron's theorem, Amadei's closed forms and the 3D FE twin (continuum/fe_3d.hpp) with the
// network's own elastic constants, measured on prisms as docs/continuum.md, "The 3D DEM's static moduli" describes.
//
// Static3.DISABLED_Table prints that section's tables (mesh size in mm from RBDEM_STATIC3_H, default 4):
//   RBDEM_STATIC3_H=4 build/tests/test_static3 --gtest_also_run_disabled_tests --gtest_filter=Static3.DISABLED_Table
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <string>
#include <vector>

#include "compare/gate/dem_constants3.hpp"
#include "compare/gate/elastic_gate3.hpp"
#include "continuum/fe_3d.hpp"
#include "dem/geometry3.hpp"
#include "dem/specimen_mesh3.hpp"
#include "dem/static3.hpp"
#include "theory/elasticity.hpp"
#include "theory/elasticity3.hpp"

namespace rbdem {
namespace {

using stages::BlockKin3;
using stages::FaceBondFrame;

// Two irregular tetrahedra on one shared face (mm scale), a rock bond of the paper scene's rock.
struct Pair {
  Vec3 ci, cj;
  FaceBondFrame frame;
};
Pair pair() {
  const double L = 1e-3;
  const Tri face{Vec3{0, 0, 0}, Vec3{1.1 * L, 0.1 * L, 0.05 * L}, Vec3{0.3 * L, 0.9 * L, -0.1 * L}};
  const Vec3 ai{0.4 * L, 0.2 * L, -1.0 * L}, aj{0.3 * L, 0.5 * L, 1.2 * L};
  Pair p;
  p.ci = 0.25 * (face[0] + face[1] + face[2] + ai);
  p.cj = 0.25 * (face[0] + face[1] + face[2] + aj);
  p.frame = stages::face_bond_frame(p.ci, p.cj, face, FaceBond{1.0 / 1.5, {}, 0.0}, 160e9,
                                    std::numeric_limits<double>::infinity());
  return p;
}

// The generalized forces (F_i, M_i, F_j, M_j) of eval_face_bond at the dofs q (u_i, phi_i, u_j, phi_j) added to a
// base state, with velocities q / dt (dt = 1 s) so that the linear part's incremental shear is its total shear.
std::array<double, 12> forces_at(const Pair& p, const std::array<double, 12>& q, Vec3 base_j) {
  auto kin = [&](Vec3 c, int o, Vec3 base) {
    const Vec3 u{q[o], q[o + 1], q[o + 2]}, phi{q[o + 3], q[o + 4], q[o + 5]};
    return BlockKin3{c + base + u, from_rotation_vector(phi), u, phi};
  };
  const auto e = stages::eval_face_bond(p.frame, kin(p.ci, 0, {}), kin(p.cj, 6, base_j), 1.0, 0.0, 0.0, 1.0);
  const Vec3 fi = -e.f;
  return {fi.x, fi.y, fi.z, e.mi.x, e.mi.y, e.mi.z, e.f.x, e.f.y, e.f.z, e.mj.x, e.mj.y, e.mj.z};
}

// The 12 x 12 matrix is minus the Jacobian of the kernel's forces: central differences about a state pressed
// together by delta0 along n, so that the linear part stays closed over the whole face under the small motions
// (its force there adds geometric terms of relative size delta0 / L = 1e-6). Rotation dofs are scaled by L so
// that every entry is in N/m.
TEST(Static3, FaceBondMatrixIsTheKernelsJacobian) {
  const Pair p = pair();
  const double L = 1e-3, delta0 = 1e-9, h = 1e-12;
  const Vec3 base_j = -delta0 * p.frame.axes.r[2];
  const FaceBondMatrix K = face_bond_stiffness(p.frame, true);
  double kmax = 0, err = 0;
  for (int c = 0; c < 12; ++c) {
    const double step = (c % 6 < 3) ? h : h / L;
    std::array<double, 12> qp{}, qm{};
    qp[std::size_t(c)] = step, qm[std::size_t(c)] = -step;
    const auto fp = forces_at(p, qp, base_j), fm = forces_at(p, qm, base_j);
    for (int r = 0; r < 12; ++r) {
      const double scale = ((r % 6 < 3) ? 1.0 : 1.0 / L) * ((c % 6 < 3) ? 1.0 : 1.0 / L);
      const double fd = -(fp[std::size_t(r)] - fm[std::size_t(r)]) / (2 * step) * scale;
      const double k = K[std::size_t(12 * r + c)] * scale;
      kmax = std::max(kmax, std::abs(k)), err = std::max(err, std::abs(fd - k));
    }
  }
  EXPECT_LT(err / kmax, 1e-5) << "max |K| " << kmax << " N/m";
  // The parallel bond alone is half the normal and shear stiffness: the closed linear part doubles them.
  const FaceBondMatrix Kpb = face_bond_stiffness(p.frame, false);
  EXPECT_NEAR(K[12 * 6 + 6] - Kpb[12 * 6 + 6], K[0] - Kpb[0], 1e-9 * K[0]);
}

// Symmetric and zero on the six rigid motions of the pair: u = t + w x c, phi = w.
TEST(Static3, FaceBondMatrixIsSymmetricAndIgnoresRigidMotion) {
  const Pair p = pair();
  const FaceBondMatrix K = face_bond_stiffness(p.frame, true);
  double kmax = 0;
  for (double k : K) kmax = std::max(kmax, std::abs(k));
  for (int r = 0; r < 12; ++r)
    for (int c = 0; c < 12; ++c) EXPECT_EQ(K[std::size_t(12 * r + c)], K[std::size_t(12 * c + r)]);
  const Vec3 t{1e-6, -2e-6, 3e-6}, w{0.7e-3, -0.4e-3, 0.9e-3};
  const Vec3 ui = t + cross(w, p.ci), uj = t + cross(w, p.cj);
  const double q[12] = {ui.x, ui.y, ui.z, w.x, w.y, w.z, uj.x, uj.y, uj.z, w.x, w.y, w.z};
  for (int r = 0; r < 12; ++r) {
    double f = 0;
    for (int c = 0; c < 12; ++c) f += K[std::size_t(12 * r + c)] * q[c];
    EXPECT_LT(std::abs(f), 1e-12 * kmax * 1e-5) << "row " << r;
  }
}


// --- the network's elastic constants, measured on prisms ---------------------------------------------------------

constexpr double dips[] = {0, 15, 30, 45, 60, 75, 90};

// The specimen: 50 mm x 100 mm, joints `spacing` apart through the centre (the paper's: 10 mm; the tests' 8 mm
// meshes take 25 mm, the widest spacing that leaves three joint planes).
const TetMesh& specimen(Shape3 shape, bool joints, double dip, double h, double spacing) {
  static std::map<std::tuple<int, bool, double, double, double>, TetMesh> cache;
  const auto key = std::make_tuple(int(shape), joints, dip, h, spacing);
  auto it = cache.find(key);
  if (it == cache.end()) {
    SpecimenGeometry3 g;
    g.shape = shape, g.joints = joints;
    g.set1 = {dip, 0.0, spacing, 0.0};
    it = cache.emplace(key, mesh_specimen3(g, h)).first;
  }
  return it->second;
}

Static3Result solve(const TetMesh& m, const Static3Options& o = {}) { return solve_static3(m, o); }

// The measurements are the library's (compare/gate/dem_constants3.hpp, what rbdem elastic runs on a 3D scene), on
// this file's cached meshes.
// Isotropic network (no joints): E and nu from a prism under uniaxial stress (the mean of the two lateral strains).
struct Isotropic {
  double E = 0, nu = 0;
};
Isotropic measure_isotropic(double h, double spacing, const Static3Options& o = {}) {
  const theory::TIConstants c =
      compare::isotropic_constants3(compare::virtual_test3(solve(specimen(Shape3::prism, false, 0.0, h, spacing), o), 0));
  return {c.E, c.nu};
}

// The jointed network's five constants from the prisms at 0, 45 and 90 deg (compare::ti_constants3).
theory::TIConstants measure_ti(double h, double spacing) {
  static std::map<std::pair<double, double>, theory::TIConstants> cache;  // the tests share them
  if (auto it = cache.find({h, spacing}); it != cache.end()) return it->second;
  auto test = [&](double dip) {
    return compare::virtual_test3(solve(specimen(Shape3::prism, true, dip, h, spacing)), dip);
  };
  return cache[{h, spacing}] = compare::ti_constants3(test(0.0), test(45.0), test(90.0));
}

// Goodman's constants (docs/theory.md, 3.1-3.2) of the isotropic network cut by the joints: k_n and k_s per unit
// area from the joint bonds' extra compliance over the rock bonds', at the joint bonds' mean d
// (compare::goodman_estimate on a scene of these bond materials).
theory::TIConstants goodman_of(const Isotropic& rock, double d_mean, double spacing, const Static3Options& o = {}) {
  Scene scene;
  scene.rock.effective_modulus = o.rock.modulus, scene.rock.stiffness_ratio = o.rock.kappa;
  scene.joint.effective_modulus = o.joint.modulus, scene.joint.stiffness_ratio = o.joint.kappa;
  scene.joint_set.spacing = spacing;
  return compare::goodman_estimate(scene, theory::TIConstants::isotropic(rock.E, rock.nu), d_mean).constants;
}

// Clapeyron: the platen's work 1/2 F delta equals the energy the bonds and the platen contacts store, and the two
// platens carry the same force (no other support is loaded).
TEST(Static3, PlatenWorkIsTheStoredEnergy) {
  const Static3Result r = solve(specimen(Shape3::cylinder, true, 60.0, 0.008, 0.025));
  EXPECT_NEAR(r.strain_energy / r.platen_work, 1.0, 1e-8);
  EXPECT_NEAR(r.bottom_force / r.top_force, 1.0, 1e-8);
  EXPECT_GT(r.joint_bonds, 0u);
}


// --- the network against the continuum (8 mm meshes, joints 25 mm apart: a few seconds in all) -------------------

constexpr double h_test = 0.008, s_test = 0.025;

// The unjointed network is isotropic: on the cylinder the two lateral strains agree, and the modulus and Poisson's
// ratio are the prism's, up to the scatter of one coarse mesh realization against another (3 % and 0.01, what
// the 8 mm meshes show; docs/continuum.md lists the 4 mm values).
TEST(Static3, UnjointedNetworkIsIsotropic) {
  const Isotropic prism = measure_isotropic(h_test, s_test);
  const TetMesh& m = specimen(Shape3::cylinder, false, 0.0, h_test, s_test);
  const Static3Result r = solve(m);
  const continuum::Fe3Result fe = continuum::solve_elastic_3d(m, theory::TIConstants::isotropic(prism.E, prism.nu),
                                                              0.0, 0.0);
  EXPECT_NEAR(r.fit_modulus / fe.mean_strain_modulus, 1.0, 0.03);
  EXPECT_NEAR(r.poisson_strike, fe.poisson_strike, 0.01);
  EXPECT_NEAR(r.poisson_dip, fe.poisson_dip, 0.01);
  EXPECT_NEAR(r.poisson_strike, r.poisson_dip, 0.01);
}

// The jointed cylinder at 0, 45 and 90 deg against the FE twin on the same tetrahedra with the five constants
// measured on prisms (at 0 and 90 deg the prism's value is a constant itself, so the cylinder's is a check of a
// different mesh; at 45 deg G' comes from the prism's 45 deg modulus). Within 5 %, the scatter at 8 mm.
TEST(Static3, JointedModulusMatchesTheFeTwinWithTheMeasuredConstants) {
  const theory::TIConstants c = measure_ti(h_test, s_test);
  ASSERT_TRUE(c.admissible());
  for (double dip : {0.0, 45.0, 90.0}) {
    const TetMesh& m = specimen(Shape3::cylinder, true, dip, h_test, s_test);
    const Static3Result r = solve(m);
    const continuum::Fe3Result fe = continuum::solve_elastic_3d(m, c, dip, 0.0);
    EXPECT_NEAR(r.fit_modulus / fe.mean_strain_modulus, 1.0, 0.05) << "dip " << dip;
    EXPECT_NEAR(r.fit_modulus / theory::amadei_uniaxial_3d(c, dip).modulus, 1.0, 0.05) << "dip " << dip;
  }
}

// The joints make the network transversely isotropic: E and nu stay the unjointed prism's (2 % and 0.01, the
// scatter between mesh realizations) and the joints add compliance across themselves. Goodman's series model
// (docs/theory.md 3.1-3.2) assumes the stress uniform over the joint plane, so that every joint bond adds its full
// extra compliance d (1/(2 E*_j) - 1/(2 E*_r)); the network carries more of the load through the stiffer bonds,
// so the joints add at most Goodman's compliance, normal and in shear. At least half of it, measured: 0.59-0.86 of
// the normal one and 0.82-0.98 of the shear one at 4-8 mm (docs/continuum.md).
TEST(Static3, JointedConstantsFollowGoodman) {
  const Isotropic rock = measure_isotropic(h_test, s_test);
  const theory::TIConstants c = measure_ti(h_test, s_test);
  const Static3Result j0 = solve(specimen(Shape3::prism, true, 0.0, h_test, s_test));
  const theory::TIConstants g = goodman_of(rock, j0.joint_d_mean, s_test);
  EXPECT_NEAR(c.E / g.E, 1.0, 0.02);
  EXPECT_NEAR(c.nu, g.nu, 0.01);
  const double G_r = rock.E / (2 * (1 + rock.nu));
  const double normal = (1 / c.E_prime - 1 / rock.E) / (1 / g.E_prime - 1 / rock.E);
  const double shear = (1 / c.G_prime - 1 / G_r) / (1 / g.G_prime - 1 / G_r);
  EXPECT_GT(normal, 0.5);
  EXPECT_LE(normal, 1.0);
  EXPECT_GT(shear, 0.5);
  EXPECT_LE(shear, 1.0);
}

// Goodman's baseline is the rock, and the rock the jointed network carries is not the unjointed prism's: the
// tetrahedra conform to the joint planes, a fabric that is stiffer across them with rock bonds in the planes
// (docs/theory.md, "The 3D network against its continuum"). From that baseline (the jointed prisms solved with
// rock bonds across the planes) Goodman's series model gives the network's five constants: the joints add their
// bonds' extra compliance 1/(k_n s), 1/(k_s s), no more and no less (2 %; 0.2-0.7 % at 3-4 mm).
TEST(Static3, JointedConstantsAreGoodmansOnTheJointedMeshRock) {
  const Scene scene = parse_scene("[specimen]\ndimension = 3\nshape = \"prism\"\n[mesh]\nsize = 0.008\n"
                                  "[joint_set]\nspacing = 0.025\n", "goodman3");
  const compare::DemConstants3 c = compare::measure_dem_constants3(scene, 2);
  ASSERT_EQ(c.fabric_tests.size(), 3u);
  ASSERT_TRUE(c.fabric.admissible() && c.goodman_fabric.admissible());
  // The fabric: across the planes the jointed mesh with rock bonds is stiffer than the unjointed prism.
  EXPECT_GT(c.fabric.E_prime / c.intact.modulus, 1.02);
  const theory::TIConstants& g = c.goodman_fabric;
  EXPECT_NEAR(c.dem.E / g.E, 1.0, 0.02);
  EXPECT_NEAR(c.dem.nu, g.nu, 0.01);
  EXPECT_NEAR(c.dem.E_prime / g.E_prime, 1.0, 0.02);
  EXPECT_NEAR(c.dem.nu_prime, g.nu_prime, 0.01);
  EXPECT_NEAR(c.dem.G_prime / g.G_prime, 1.0, 0.02);
  // The joints are a large part of the compliance across them, so the check has content.
  EXPECT_LT(g.E_prime / c.fabric.E_prime, 0.9);
}

// With k_s = k_n (kappa = 1) a face bond's translational spring is isotropic and the network has no Poisson
// effect (the affine estimate (kappa - 1) / (4 kappa + 1) of a random spring network is 0 there); Poisson's ratio
// grows with kappa.
TEST(Static3, PoissonsRatioGrowsWithTheStiffnessRatio) {
  double last = -1;
  for (double kappa : {1.0, 1.5, 3.0}) {
    Static3Options o;
    o.rock.kappa = o.joint.kappa = kappa;
    const Isotropic k = measure_isotropic(h_test, s_test, o);
    if (kappa == 1.0) {
      EXPECT_NEAR(k.nu, 0.0, 0.005);
    }
    EXPECT_GT(k.nu, last) << "kappa " << kappa;
    last = k.nu;
  }
}

// The iterative solver (CG with incomplete Cholesky) gives the direct solver's answer to its tolerance.
TEST(Static3, IterativeSolveMatchesTheDirectOne) {
  const TetMesh& m = specimen(Shape3::cylinder, false, 0.0, 0.012, s_test);
  Static3Options o;
  o.solver = Static3Solver::ldlt;
  const Static3Result direct = solve(m, o);
  o.solver = Static3Solver::cg;
  const Static3Result cg = solve(m, o);
  EXPECT_TRUE(direct.direct);
  EXPECT_FALSE(cg.direct);
  EXPECT_GT(cg.iterations, 0);
  EXPECT_NEAR(cg.fit_modulus / direct.fit_modulus, 1.0, 1e-7);
  EXPECT_NEAR(cg.platen_modulus / direct.platen_modulus, 1.0, 1e-7);
  EXPECT_NEAR(cg.poisson_dip, direct.poisson_dip, 1e-7);
}

TEST(Static3, BadInputIsRejectedByName) {
  const TetMesh& m = specimen(Shape3::prism, false, 0.0, h_test, s_test);
  Static3Options o;
  o.platen_displacement = -1e-6;
  EXPECT_THROW(solve_static3(m, o), std::invalid_argument);
  o = {}, o.joint.kappa = 0;
  EXPECT_THROW(solve_static3(m, o), std::invalid_argument);
  EXPECT_THROW(solve_static3(TetMesh{}, {}), std::invalid_argument);
}

// The 3D elastic gate refuses, before any solve, what it cannot measure: a 2D scene, a second joint set (the five
// constants are of one set) and a user mesh (it meshes every dip).
TEST(ElasticGate3, RefusesWhatItCannotMeasure) {
  const std::string d3 = "[specimen]\ndimension = 3\n";
  for (const auto& [toml, key] : {std::pair<std::string, std::string>{"", "specimen.dimension"},
                                  {d3 + "[joint_set2]\nenabled = true\nspacing = 0.02\n", "joint_set2.enabled"},
                                  {d3 + "[mesh]\nfile = \"user.msh\"\n", "mesh.file"}}) {
    try {
      compare::run_elastic_gate3(parse_scene(toml, "gate3"));
      ADD_FAILURE() << toml;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

void print_table(double h, double spacing) {
  const Isotropic iso = measure_isotropic(h, spacing);
  const theory::TIConstants c = measure_ti(h, spacing);
  const Static3Result j0 = solve(specimen(Shape3::prism, true, 0.0, h, spacing));
  const theory::TIConstants g = goodman_of(iso, j0.joint_d_mean, spacing);
  std::printf("h = %g mm: isotropic E %.2f GPa nu %.4f\n", h * 1e3, iso.E / 1e9, iso.nu);
  std::printf("measured: E %.2f nu %.4f E' %.2f nu' %.4f G' %.2f\n", c.E / 1e9, c.nu, c.E_prime / 1e9, c.nu_prime,
              c.G_prime / 1e9);
  std::printf("goodman : E %.2f nu %.4f E' %.2f nu' %.4f G' %.2f (d_mean %.3f mm)\n", g.E / 1e9, g.nu,
              g.E_prime / 1e9, g.nu_prime, g.G_prime / 1e9, j0.joint_d_mean * 1e3);
  const theory::TIConstants gh = goodman_of(iso, j0.joint_d_harmonic, spacing);
  std::printf("goodman, harmonic d: E' %.2f nu' %.4f G' %.2f (d_harmonic %.3f mm)\n", gh.E_prime / 1e9,
              gh.nu_prime, gh.G_prime / 1e9, j0.joint_d_harmonic * 1e3);
  const double G_r = iso.E / (2 * (1 + iso.nu));
  std::printf("joint compliance / Goodman's: normal %.3f shear %.3f\n",
              (1 / c.E_prime - 1 / iso.E) / (1 / g.E_prime - 1 / iso.E),
              (1 / c.G_prime - 1 / G_r) / (1 / g.G_prime - 1 / G_r));
  std::printf("prism at 0 deg: %zu blocks, %zu dofs, assembly %.2f s, solve %.2f s\n", j0.blocks, j0.dofs,
              j0.assemble_seconds, j0.solve_seconds);
  std::fflush(stdout);
  std::printf("dip | DEM fit | DEM platen | FE mean-strain | FE platen | Amadei | fit/Amadei-1 | platen/FE-1 | "
              "nu_s DEM Amadei | nu_d DEM Amadei | blocks dofs asm solve CG-it | FE dofs solve\n");
  for (double dip : dips) {
    const TetMesh& m = specimen(Shape3::cylinder, true, dip, h, spacing);
    const Static3Result r = solve(m);
    const continuum::Fe3Result fe = continuum::solve_elastic_3d(m, c, dip, 0.0);
    const theory::Uniaxial3 a = theory::amadei_uniaxial_3d(c, dip);
    std::printf("%2.0f | %.2f | %.2f | %.2f | %.2f | %.2f | %+.4f | %+.4f | %.4f %.4f | %.4f %.4f | "
                "%zu %zu %.2f %.2f %d | %zu %.2f\n",
                dip, r.fit_modulus / 1e9, r.platen_modulus / 1e9, fe.mean_strain_modulus / 1e9,
                fe.apparent_modulus / 1e9, a.modulus / 1e9, r.fit_modulus / a.modulus - 1,
                r.platen_modulus / fe.apparent_modulus - 1, r.poisson_strike, a.poisson_strike, r.poisson_dip,
                a.poisson_dip, r.blocks, r.dofs, r.assemble_seconds, r.solve_seconds, r.iterations, fe.dofs,
                fe.setup_seconds + fe.assemble_seconds + fe.solve_seconds);
    std::fflush(stdout);
  }
  std::fflush(stdout);
  if (std::getenv("RBDEM_STATIC3_NO_KAPPA")) return;
  std::printf("nu against kappa (isotropic prism):\n");
  for (double kappa : {1.0, 1.5, 2.0, 3.0, 5.0, 10.0}) {
    Static3Options o;
    o.rock.kappa = o.joint.kappa = kappa;
    const Isotropic k = measure_isotropic(h, spacing, o);
    std::printf("kappa %.1f: E %.2f GPa nu %.4f  (affine (k-1)/(4k+1) = %.4f)\n", kappa, k.E / 1e9, k.nu,
                (kappa - 1) / (4 * kappa + 1));
  }
}

// The strain fitted to the centroid displacements of the blocks in a central gauge only: |z - z_mid| <= H/4 and,
// horizontally, within half the half-width of the axis (least squares over the blocks' centroids, unweighted).
// Free of the layers along the platens and the free side.
std::array<double, 6> gauge_strain(const TetMesh& m, const std::vector<double>& u) {
  double lo[3] = {1e9, 1e9, 1e9}, hi[3] = {-1e9, -1e9, -1e9};
  for (const auto& p : m.nodes)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[std::size_t(k)]), hi[k] = std::max(hi[k], p[std::size_t(k)]);
  std::vector<Vec3> c;
  std::vector<double> du;
  for (std::size_t t = 0; t < m.num_tets(); ++t) {
    Vec3 x{};
    for (int n : m.tets[t]) {
      const auto& p = m.nodes[std::size_t(n)];
      x += 0.25 * Vec3{p[0], p[1], p[2]};
    }
    const double zm = 0.5 * (lo[2] + hi[2]), xm = 0.5 * (lo[0] + hi[0]), ym = 0.5 * (lo[1] + hi[1]);
    const double half = 0.5 * (hi[0] - lo[0]);
    if (std::abs(x.z - zm) > 0.25 * (hi[2] - lo[2]) || std::hypot(x.x - xm, x.y - ym) > 0.5 * half) continue;
    c.push_back(x);
    du.insert(du.end(), {u[6 * t], u[6 * t + 1], u[6 * t + 2]});
  }
  Vec3 mean{};
  for (const Vec3& x : c) mean += (1.0 / double(c.size())) * x;
  double M[3][3] = {}, R[3][3] = {};
  for (std::size_t b = 0; b < c.size(); ++b) {
    const double d[3] = {c[b].x - mean.x, c[b].y - mean.y, c[b].z - mean.z};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) M[i][j] += d[i] * d[j], R[i][j] += du[3 * b + std::size_t(i)] * d[j];
  }
  // G = R M^-1 by Cramer on the symmetric 3 x 3 M.
  const double det = M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
                     M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
  double Mi[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const int a = (j + 1) % 3, b = (j + 2) % 3, cc = (i + 1) % 3, d = (i + 2) % 3;
      Mi[i][j] = (M[a][cc] * M[b][d] - M[a][d] * M[b][cc]) / det;
    }
  double G[3][3] = {};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int k = 0; k < 3; ++k) G[i][j] += R[i][k] * Mi[k][j];
  return {G[0][0], G[1][1], G[2][2], 0.5 * (G[1][2] + G[2][1]), 0.5 * (G[0][2] + G[2][0]), 0.5 * (G[0][1] + G[1][0])};
}

// Where the cylinder departs from the prisms' continuum (docs/continuum.md, "The gate at 3 mm"): each specimen's
// modulus from the fit over all blocks, from the central gauge and from the platens, the prisms' five constants
// from either fit, and Amadei with them. RBDEM_STATIC3_H (mm, default 4), RBDEM_STATIC3_DIPS (comma list),
// RBDEM_STATIC3_PRISM=1: those dips on prisms.
TEST(Static3, DISABLED_GaugeAgainstFit) {
  const double h = (std::getenv("RBDEM_STATIC3_H") ? std::atof(std::getenv("RBDEM_STATIC3_H")) : 4.0) * 1e-3;
  const double spacing = 0.01;
  auto gauge_test = [&](const TetMesh& m, const Static3Result& r, double dip) {
    Static3Result g = r;
    const auto e = gauge_strain(m, r.u);
    g.fit_modulus = r.mean_stress / -e[2];
    g.poisson_strike = -e[1] / e[2], g.poisson_dip = -e[0] / e[2];  // dip direction 0: strike y, dip x
    return compare::virtual_test3(g, dip);
  };
  for (Shape3 shape : {Shape3::prism, Shape3::cylinder}) {  // the unjointed specimens
    const TetMesh& m = specimen(shape, false, 0.0, h, spacing);
    const Static3Result r = solve(m);
    std::printf("unjointed %s: fit %.2f gauge %.2f platen %.2f GPa, %zu blocks\n",
                shape == Shape3::prism ? "prism" : "cylinder", r.fit_modulus / 1e9,
                gauge_test(m, r, 0.0).modulus / 1e9, r.platen_modulus / 1e9, r.blocks);
    std::fflush(stdout);
  }
  std::map<double, compare::VirtualTest3> fit, gauge;
  for (double dip : {0.0, 45.0, 90.0}) {
    const TetMesh& m = specimen(Shape3::prism, true, dip, h, spacing);
    const Static3Result r = solve(m);
    fit[dip] = compare::virtual_test3(r, dip), gauge[dip] = gauge_test(m, r, dip);
    std::printf("prism %2.0f: fit %.2f gauge %.2f platen %.2f GPa\n", dip, r.fit_modulus / 1e9,
                gauge[dip].modulus / 1e9, r.platen_modulus / 1e9);
    std::fflush(stdout);
  }
  const theory::TIConstants cf = compare::ti_constants3(fit[0], fit[45], fit[90]);
  const theory::TIConstants cg = compare::ti_constants3(gauge[0], gauge[45], gauge[90]);
  std::printf("constants fit:   E %.2f E' %.2f G' %.2f nu %.4f nu' %.4f\n", cf.E / 1e9, cf.E_prime / 1e9,
              cf.G_prime / 1e9, cf.nu, cf.nu_prime);
  std::printf("constants gauge: E %.2f E' %.2f G' %.2f nu %.4f nu' %.4f\n", cg.E / 1e9, cg.E_prime / 1e9,
              cg.G_prime / 1e9, cg.nu, cg.nu_prime);
  std::vector<double> list{15, 60, 75, 90};
  if (const char* d = std::getenv("RBDEM_STATIC3_DIPS")) {
    list.clear();
    for (std::string s = d; !s.empty();) {
      const auto k = s.find(',');
      list.push_back(std::atof(s.substr(0, k).c_str()));
      s = k == std::string::npos ? "" : s.substr(k + 1);
    }
  }
  const bool prism = std::getenv("RBDEM_STATIC3_PRISM") != nullptr;  // the list on prisms instead
  for (double dip : list) {
    const TetMesh& m = specimen(prism ? Shape3::prism : Shape3::cylinder, true, dip, h, spacing);
    const Static3Result r = solve(m);
    const double eg = gauge_test(m, r, dip).modulus;
    const double af = theory::amadei_uniaxial_3d(cf, dip).modulus, ag = theory::amadei_uniaxial_3d(cg, dip).modulus;
    std::printf("%s %2.0f: fit %.2f (Amadei-fit %.2f, %+.2f %%) gauge %.2f (Amadei-gauge %.2f, %+.2f %%) "
                "platen %.2f GPa, %zu blocks\n",
                prism ? "prism" : "cylinder", dip, r.fit_modulus / 1e9, af / 1e9, 100 * (r.fit_modulus / af - 1), eg / 1e9, ag / 1e9,
                100 * (eg / ag - 1), r.platen_modulus / 1e9, r.blocks);
    std::fflush(stdout);
  }
}

// Goodman's k_n from the joint bonds side by side (docs/theory.md, 11.11): the 0 deg prism's joint faces, their
// centroid distances d (area-weighted mean, harmonic mean A / sum(A / d), quartiles), Goodman's E' at either d
// against the measured E'. RBDEM_STATIC3_H (mm, default 4).
TEST(Static3, DISABLED_JointDistances) {
  const double h = (std::getenv("RBDEM_STATIC3_H") ? std::atof(std::getenv("RBDEM_STATIC3_H")) : 4.0) * 1e-3;
  const double spacing = 0.01;
  const TetMesh& m = specimen(Shape3::prism, true, 0.0, h, spacing);
  auto centre = [&](int t) {
    Vec3 x{};
    for (int n : m.tets[std::size_t(t)]) x += 0.25 * Vec3{m.nodes[std::size_t(n)][0], m.nodes[std::size_t(n)][1],
                                                         m.nodes[std::size_t(n)][2]};
    return x;
  };
  double A = 0, Ad = 0, A_over_d = 0;
  std::vector<double> d;
  for (const SharedFace& f : shared_faces(m)) {
    if (!f.joint) continue;
    auto node = [&](int k) {
      const auto& p = m.nodes[std::size_t(f.nodes[std::size_t(k)])];
      return Vec3{p[0], p[1], p[2]};
    };
    const Face face = face_of({node(0), node(1), node(2)});
    const double dist = dot(face.normal, centre(f.tets[1]) - centre(f.tets[0]));
    A += face.area, Ad += face.area * dist, A_over_d += face.area / dist;
    d.push_back(dist);
  }
  std::sort(d.begin(), d.end());
  const double d_mean = Ad / A, d_harm = A / A_over_d;
  std::printf("h %g mm: %zu joint faces, d mean %.3f mm, harmonic %.3f mm (ratio %.3f), quartiles %.3f %.3f %.3f, "
              "min %.3f max %.3f mm\n",
              h * 1e3, d.size(), d_mean * 1e3, d_harm * 1e3, d_harm / d_mean, d[d.size() / 4] * 1e3,
              d[d.size() / 2] * 1e3, d[3 * d.size() / 4] * 1e3, d.front() * 1e3, d.back() * 1e3);
  std::fflush(stdout);
  const Isotropic iso = measure_isotropic(h, spacing);
  const theory::TIConstants c = measure_ti(h, spacing);
  const theory::TIConstants gm = goodman_of(iso, d_mean, spacing), gh = goodman_of(iso, d_harm, spacing);
  auto share = [&](double Ep) { return (1 / Ep - 1 / iso.E) / (1 / gm.E_prime - 1 / iso.E); };
  std::printf("E_r %.2f GPa; E' measured %.2f, Goodman at d_mean %.2f, at d_harmonic %.2f GPa; joint compliance / "
              "Goodman's (d_mean): measured %.3f, at d_harmonic %.3f\n",
              iso.E / 1e9, c.E_prime / 1e9, gm.E_prime / 1e9, gh.E_prime / 1e9, share(c.E_prime),
              share(gh.E_prime));
}

// The joints' share of Goodman's normal compliance against the joint's stiffness: E' of the 0 deg prism with the
// joint's E* from the rock's (the jointed mesh with rock bonds across the planes) down to an eighth of it, against
// the unjointed prism's E_r and against the jointed mesh's own E' at E*_j = E*_r (8 mm, joints 25 mm apart: a few
// seconds each; RBDEM_STATIC3_H, RBDEM_STATIC3_SPACING in mm, RBDEM_STATIC3_EJ one joint E* in GPa).
TEST(Static3, DISABLED_JointShareAgainstStiffness) {
  const double h = (std::getenv("RBDEM_STATIC3_H") ? std::atof(std::getenv("RBDEM_STATIC3_H")) : 8.0) * 1e-3;
  const double spacing = std::getenv("RBDEM_STATIC3_SPACING") ? std::atof(std::getenv("RBDEM_STATIC3_SPACING")) * 1e-3
                                                               : s_test;
  const Isotropic iso = measure_isotropic(h, spacing);
  const TetMesh& m = specimen(Shape3::prism, true, 0.0, h, spacing);
  Static3Options same;
  same.joint = same.rock;
  const double E_mesh = solve(m, same).fit_modulus;
  std::printf("E_r (unjointed prism) %.2f GPa; the jointed prism with rock bonds across the planes %.2f GPa\n",
              iso.E / 1e9, E_mesh / 1e9);
  std::vector<double> joint_moduli{120e9, 80e9, 50e9, 20e9};
  if (const char* e = std::getenv("RBDEM_STATIC3_EJ")) joint_moduli = {std::atof(e) * 1e9};  // GPa
  for (double Ej : joint_moduli) {
    Static3Options o;
    o.joint.modulus = Ej;
    const Static3Result r = solve(m, o);
    const theory::TIConstants g = goodman_of(iso, r.joint_d_mean, spacing, o);
    const double goodman = 1 / g.E_prime - 1 / iso.E;
    std::printf("E*_j %.0f GPa: E' %.2f GPa, Goodman %.2f GPa; joint compliance / Goodman's: over E_r %.3f, over "
                "the jointed mesh's own %.3f\n",
                Ej / 1e9, r.fit_modulus / 1e9, g.E_prime / 1e9, (1 / r.fit_modulus - 1 / iso.E) / goodman,
                (1 / r.fit_modulus - 1 / E_mesh) / goodman);
    std::fflush(stdout);
  }
}

// The cylinder at one dip with its joint planes shifted (offset in mm, a comma list): where the planes cut thin
// circular segments off the side, and where they do not. RBDEM_STATIC3_H (mm, default 3), RBDEM_STATIC3_DIP (90).
TEST(Static3, DISABLED_CylinderOffsets) {
  const double h = (std::getenv("RBDEM_STATIC3_H") ? std::atof(std::getenv("RBDEM_STATIC3_H")) : 3.0) * 1e-3;
  const double dip = std::getenv("RBDEM_STATIC3_DIP") ? std::atof(std::getenv("RBDEM_STATIC3_DIP")) : 90.0;
  for (double offset : {0.0, 2.5, 5.0}) {
    SpecimenGeometry3 g;
    g.joints = true;
    g.set1 = {dip, 0.0, 0.01, offset * 1e-3};
    const Static3Result r = solve(mesh_specimen3(g, h));
    std::printf("cylinder, dip %.0f, joints offset %.1f mm: fit %.2f platen %.2f GPa, %zu blocks\n", dip, offset,
                r.fit_modulus / 1e9, r.platen_modulus / 1e9, r.blocks);
    std::fflush(stdout);
  }
}

TEST(Static3, DISABLED_Table) {
  const char* env = std::getenv("RBDEM_STATIC3_H");
  const char* s = std::getenv("RBDEM_STATIC3_SPACING");
  print_table((env ? std::atof(env) : 4.0) * 1e-3, (s ? std::atof(s) : 10.0) * 1e-3);
}

}  // namespace
}  // namespace rbdem
