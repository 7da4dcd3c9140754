// The 3D FE twin with the joints as interfaces (continuum/fe_joints3.hpp) against the closed forms it must meet:
// glued interfaces are the continuum of fe_3d.hpp; on a prism between frictionless platens the uniform uniaxial
// stress is the exact solution, so horizontal joints add their compliance in series (Goodman), vertical joints add
// nothing, also where two sets cross; a joint set at 45 deg tends to Goodman's TI medium as the spacing falls; stiff
// joints tend to the unjointed solution. Meshes from the 3D mesher (mesh_specimen3), small.
//
// FeJoints3.DISABLED_CostTable prints the costs of docs/continuum.md on the 4 and 3 mm cylinders of
// scenes/cylinder.toml (60 deg, joints every 10 mm):
//   build/tests/test_fe_joints3 --gtest_also_run_disabled_tests --gtest_filter=FeJoints3.DISABLED_CostTable
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>

#include "continuum/fe_3d.hpp"
#include "continuum/fe_joints3.hpp"
#include "dem/specimen_mesh3.hpp"
#include "theory/elasticity3.hpp"

namespace rbdem::continuum {
namespace {

using theory::TIConstants;
constexpr double inf = std::numeric_limits<double>::infinity();
const TIConstants layered{60e9, 0.2, 25e9, 0.12, 9e9};  // clearly anisotropic: E/E' = 2.4
constexpr double W = 0.05, H = 0.1;                      // the prism: 50 x 50 x 100 mm

// A mesh of the prism or the cylinder cut by one set (and optionally a second) of joint planes.
// `depth`: the prism's along y (the strike at dip direction 0).
const TetMesh& specimen(Shape3 shape, JointPlaneSet set1, double h, bool second = false, JointPlaneSet set2 = {},
                        double depth = W) {
  static std::map<std::tuple<int, double, double, double, double, bool, double, double, double, double>, TetMesh>
      cache;
  const auto key = std::make_tuple(int(shape), set1.dip_deg, set1.dip_direction_deg, set1.spacing, h, second,
                                   set2.dip_deg, set2.dip_direction_deg, set2.spacing, depth);
  auto it = cache.find(key);
  if (it == cache.end()) {
    SpecimenGeometry3 g;
    g.shape = shape;
    g.depth = depth;
    g.set1 = set1;
    g.second_set = second;
    g.set2 = set2;
    it = cache.emplace(key, mesh_specimen3(g, h)).first;
  }
  return it->second;
}

std::vector<TIConstants> same_for_all(const TetMesh& m, const TIConstants& c) {
  return std::vector<TIConstants>(std::max<std::size_t>(m.num_layers(), 1), c);
}

Fe3Options direct() {
  Fe3Options o;
  o.solver = Solver::direct;
  return o;
}

// ---- Glued joints ------------------------------------------------------------------------------------------------

// Glued interfaces on every joint face tie the copies back together: the continuum of solve_elastic_3d, to
// round-off, between frictionless and bonded platens.
void expect_glued_equals_continuum(Shape3 shape, double dip, double dd) {
  for (const Platens platens : {Platens::frictionless, Platens::bonded}) {
    const TetMesh& m = specimen(shape, {dip, dd, 0.025, 0.0}, 0.012);
    Fe3Options o = direct();
    o.platens = platens;
    const Fe3Result ref = solve_elastic_3d(m, layered, dip, dd, o);
    const auto glued = joint_interfaces(m, inf, inf);
    const JointedFe3Result r = solve_elastic_3d_jointed(m, same_for_all(m, layered), dip, dd, glued, o);
    ASSERT_GT(glued.size(), 0u);
    EXPECT_EQ(r.glued_faces, glued.size());
    EXPECT_GT(r.duplicated_nodes, 0u);
    EXPECT_EQ(r.copies, m.num_nodes() + r.duplicated_nodes);
    EXPECT_EQ(r.dofs, 3 * r.copies);
    const double error = std::abs(r.apparent_modulus / ref.apparent_modulus - 1);
    std::printf("glued %-8s dip %2.0f %-12s E_app %.10e Pa  |E/E_cont - 1| = %.1e  (%zu faces, %zu copies)\n",
                shape == Shape3::prism ? "prism" : "cylinder", dip,
                platens == Platens::bonded ? "bonded" : "frictionless", r.apparent_modulus, error, glued.size(),
                r.duplicated_nodes);
    EXPECT_LT(error, 1e-11);
    EXPECT_NEAR(r.mean_strain_modulus / ref.mean_strain_modulus, 1.0, 1e-11);
    EXPECT_NEAR(r.axial_force / ref.axial_force, 1.0, 1e-11);
    EXPECT_NEAR(r.poisson_strike, ref.poisson_strike, 1e-11);
    EXPECT_NEAR(r.poisson_dip, ref.poisson_dip, 1e-11);
    EXPECT_NEAR(r.volume, ref.volume, 1e-15);
  }
}

TEST(FeJoints3, GluedJointsReproduceTheContinuumOnAPrism) { expect_glued_equals_continuum(Shape3::prism, 30, 20); }
TEST(FeJoints3, GluedJointsReproduceTheContinuumOnACylinder) { expect_glued_equals_continuum(Shape3::cylinder, 60, 0); }

// ---- Joints normal and parallel to the load (Goodman's series model) ----------------------------------------------

// Frictionless platens, horizontal joints every 25 mm in a 100 mm prism (3 planes), identical layers: the stress is
// uniform (0, 0, -sigma) in every layer, so no joint slides and each closes by sigma / k_n:
//   delta = sigma H / E_z + n sigma / k_n  ->  H / E_app = H / E_z + n / k_n,
// E_z the rock's vertical modulus (E for isotropic rock, E' for the TI rock at dip 0). Exact for P1.
TEST(FeJoints3, HorizontalJointsAddTheirComplianceInSeries) {
  const TetMesh& m = specimen(Shape3::prism, {0, 0, 0.025, 0.0}, 0.0125);
  const auto iso = TIConstants::isotropic(20e9, 0.25);
  for (const TIConstants& rock : {iso, layered})
    for (const double kn : {0.5 * rock.E_prime / H, 10 * rock.E_prime / H}) {
      const auto f = joint_interfaces(m, kn, 0.4 * kn);
      const JointedFe3Result r = solve_elastic_3d_jointed(m, same_for_all(m, rock), 0, 0, f, direct());
      const double n = 3;
      const double expected = H / (H / rock.E_prime + n / kn);
      const double error = std::abs(r.apparent_modulus / expected - 1);
      std::printf("horizontal joints E_z %.0f GPa, k_n H/E_z = %4.1f: E_app %.12e Pa, closed form %.12e Pa, error "
                  "%.1e\n", rock.E_prime / 1e9, kn * H / rock.E_prime, r.apparent_modulus, expected, error);
      EXPECT_LT(error, 1e-11);
      EXPECT_NEAR(r.mean_strain_modulus / expected, 1.0, 1e-11);  // the prism's mean strain is -delta / H
      // The lateral strains are the rock's, nu' sigma / E' (S_13 = -nu'/E' at dip 0): the joints do not slide.
      const double sigma = r.axial_force / (W * W);
      EXPECT_NEAR(r.strain_strike / (rock.nu_prime * sigma / rock.E_prime), 1.0, 1e-10);
      EXPECT_NEAR(r.strain_dip / (rock.nu_prime * sigma / rock.E_prime), 1.0, 1e-10);
      ASSERT_EQ(r.interface_opening.size(), f.size());
      for (std::size_t k = 0; k < f.size(); ++k) {
        EXPECT_NEAR(r.interface_opening[k] / (-sigma / kn), 1.0, 1e-9);
        EXPECT_LT(r.interface_slip[k], 1e-9 * sigma / kn);
      }
    }
}

// Vertical joints (dip 90) carry no traction under a uniform vertical stress: the modulus and the lateral strains
// are the rock's, whatever k_n, k_s, exactly. Crossed by horizontal joints (a second set, dip 0): the crossing
// lines split their nodes four ways and the horizontal joints alone add their compliance, exactly.
TEST(FeJoints3, VerticalJointsChangeNothingAlsoWhereTwoSetsCross) {
  const double E = 20e9, nu = 0.25, kn = 0.5 * E / H, ks = 0.2 * E / H;
  const auto rock = TIConstants::isotropic(E, nu);
  {
    const TetMesh& m = specimen(Shape3::prism, {90, 0, 0.0125, 0.0}, 0.0125);
    const auto f = joint_interfaces(m, kn, ks);
    const JointedFe3Result r = solve_elastic_3d_jointed(m, same_for_all(m, rock), 90, 0, f, direct());
    std::printf("vertical joints (%zu faces): E_app / E - 1 = %.1e, nu_strike - nu = %.1e, nu_dip - nu = %.1e\n",
                f.size(), r.apparent_modulus / E - 1, r.poisson_strike - nu, r.poisson_dip - nu);
    EXPECT_GT(f.size(), 0u);
    EXPECT_NEAR(r.apparent_modulus / E, 1.0, 1e-11);
    EXPECT_NEAR(r.poisson_strike, nu, 1e-10);
    EXPECT_NEAR(r.poisson_dip, nu, 1e-10);
  }
  // Set 1 horizontal every 25 mm (3 planes), set 2 vertical through the centre (x = 25 mm, 1 plane).
  const TetMesh& m = specimen(Shape3::prism, {0, 0, 0.025, 0.0}, 0.0125, true, {90, 0, 0.025, 0.0});
  auto f = joint_interfaces(m, kn, ks, 0);
  const auto vertical = joint_interfaces(m, 3 * kn, 3 * ks, 1);
  ASSERT_GT(vertical.size(), 0u);
  f.insert(f.end(), vertical.begin(), vertical.end());
  const std::vector<int> copies = count_node_copies3(m, f);
  std::size_t four = 0;
  for (std::size_t v = 0; v < copies.size(); ++v) {
    const auto& p = m.nodes[v];
    const bool on_crossing = std::abs(p[0] - 0.025) < 1e-9 &&
                             (std::abs(p[2] - 0.025) < 1e-9 || std::abs(p[2] - 0.05) < 1e-9 ||
                              std::abs(p[2] - 0.075) < 1e-9);
    if (on_crossing) {
      EXPECT_EQ(copies[v], 4) << "node " << v;
    }
    four += copies[v] == 4;
  }
  const JointedFe3Result r = solve_elastic_3d_jointed(m, same_for_all(m, rock), 0, 0, f, direct());
  const double expected = H / (H / E + 3 / kn);
  std::printf("crossing sets: %zu nodes in 4 copies, E_app %.12e Pa, closed form %.12e Pa, error %.1e\n", four,
              r.apparent_modulus, expected, r.apparent_modulus / expected - 1);
  EXPECT_GT(four, 3u);
  EXPECT_EQ(*std::max_element(copies.begin(), copies.end()), 4);
  EXPECT_NEAR(r.apparent_modulus / expected, 1.0, 1e-11);
  // The lateral strains are the rock's, nu sigma / E: no joint opens or slides sideways.
  const double sigma = r.axial_force / (W * W);
  EXPECT_NEAR(r.strain_strike / (nu * sigma / E), 1.0, 1e-10);
  EXPECT_NEAR(r.strain_dip / (nu * sigma / E), 1.0, 1e-10);
}

// ---- A joint that ends inside the specimen -----------------------------------------------------------------------

// One horizontal joint at mid-height, cut only where x < W/2: the joint's edge inside the specimen keeps one copy
// of its nodes (the star is connected around it), the rest of the joint two. Minimum potential energy under the
// prescribed platen displacement orders the moduli: the half joint is the whole joint with half of it glued, so
// stiffer than the whole joint and softer than no joint.
TEST(FeJoints3, JointEndingInsideTheSpecimenKeepsOneCopyAtItsEdge) {
  const TetMesh& m = specimen(Shape3::prism, {0, 0, 0.5, 0.0}, 0.0125);  // one plane, z = 50 mm
  const double E = 20e9, kn = 0.5 * E / H;
  const auto rock = TIConstants::isotropic(E, 0.25);
  const auto whole = joint_interfaces(m, kn, 0.4 * kn);
  std::vector<InterfaceFace> half;
  std::set<int> cut, kept;  // the nodes of the faces cut and of the faces left whole
  for (const InterfaceFace& f : whole) {
    double x = 0;  // the face's centroid: the mean of the nodes the two tetrahedra share
    std::vector<int> shared;
    for (int a : m.tets[std::size_t(f.tet_a)])
      for (int b : m.tets[std::size_t(f.tet_b)])
        if (a == b) shared.push_back(a), x += m.nodes[std::size_t(a)][0] / 3;
    (x < W / 2 ? cut : kept).insert(shared.begin(), shared.end());
    if (x < W / 2) half.push_back(f);
  }
  ASSERT_GT(half.size(), 0u);
  const std::vector<int> copies = count_node_copies3(m, half);
  for (int v : cut) EXPECT_EQ(copies[std::size_t(v)], kept.count(v) ? 1 : 2) << "node " << v;
  std::size_t split = 0;
  for (std::size_t v = 0; v < copies.size(); ++v)
    if (!cut.count(int(v))) {
      EXPECT_EQ(copies[v], 1);
    } else {
      split += copies[v] == 2;
    }
  const double none = solve_elastic_3d(m, rock, 0, 0, direct()).apparent_modulus;
  const JointedFe3Result r_half = solve_elastic_3d_jointed(m, same_for_all(m, rock), 0, 0, half, direct());
  const JointedFe3Result r_whole = solve_elastic_3d_jointed(m, same_for_all(m, rock), 0, 0, whole, direct());
  std::printf("joint ending inside: %zu of %zu cut nodes split; E_app (GPa) none %.4f, half %.4f, whole %.4f\n",
              split, cut.size(), none / 1e9, r_half.apparent_modulus / 1e9, r_whole.apparent_modulus / 1e9);
  EXPECT_GT(split, 0u);
  EXPECT_EQ(r_half.duplicated_nodes, split);
  EXPECT_LT(r_whole.apparent_modulus, r_half.apparent_modulus * (1 - 1e-3));
  EXPECT_LT(r_half.apparent_modulus, none * (1 - 1e-3));
  EXPECT_EQ(r_half.inert_faces, 0u);
  // One face alone: all its nodes lie on its edge, so it has no jump and changes nothing (reported as inert).
  const JointedFe3Result r_one = solve_elastic_3d_jointed(m, same_for_all(m, rock), 0, 0, {whole[whole.size() / 2]},
                                                          direct());
  EXPECT_EQ(r_one.inert_faces, 1u);
  EXPECT_EQ(r_one.duplicated_nodes, 0u);
  EXPECT_NEAR(r_one.apparent_modulus / none, 1.0, 1e-12);
}

// ---- A material per layer ----------------------------------------------------------------------------------------

// The volume of each layer, m^3.
std::vector<double> layer_volumes(const TetMesh& m) {
  std::vector<double> v(m.num_layers(), 0.0);
  for (std::size_t t = 0; t < m.num_tets(); ++t) v[std::size_t(m.layer[t])] += tet_volume(m, t);
  return v;
}

// Layers alternating two rocks (E 20 and 50 GPa). Horizontal layers with joints, no Poisson effect (nu = 0): the
// layers in series under one stress, H / E_app = sum h_l / E_l + n / k_n. Vertical layers with joints, one
// Poisson's ratio: the layers in parallel under one strain, no joint loaded, E_app = sum V_l E_l / V. Both exact.
TEST(FeJoints3, LayersOfTwoRocksInSeriesAndInParallel) {
  const double E[2] = {20e9, 50e9}, kn = 0.5 * E[0] / H;
  for (const double dip : {0.0, 90.0}) {
    const double nu = dip == 0 ? 0.0 : 0.25;
    const TetMesh& m = specimen(Shape3::prism, {dip, 0, dip == 0 ? 0.025 : 0.0125, 0.0}, 0.0125);
    std::vector<TIConstants> rocks;
    for (std::size_t l = 0; l < m.num_layers(); ++l) rocks.push_back(TIConstants::isotropic(E[l % 2], nu));
    const auto f = joint_interfaces(m, kn, 0.4 * kn);
    const JointedFe3Result r = solve_elastic_3d_jointed(m, rocks, dip, 0, f, direct());
    const std::vector<double> v = layer_volumes(m);
    double series = double(m.num_layers() - 1) / kn, parallel = 0;  // compliance H / E, modulus
    for (std::size_t l = 0; l < v.size(); ++l) series += v[l] / (W * W) / E[l % 2], parallel += v[l] * E[l % 2];
    const double expected = dip == 0 ? H / series : parallel / (W * W * H);
    std::printf("two rocks dip %2.0f (%zu layers): E_app %.12e Pa, closed form %.12e Pa, error %.1e\n", dip,
                m.num_layers(), r.apparent_modulus, expected, r.apparent_modulus / expected - 1);
    EXPECT_EQ(m.num_layers(), 4u);
    EXPECT_NEAR(r.apparent_modulus / expected, 1.0, 1e-11) << "dip " << dip;
  }
}

// ---- A fine joint set tends to Goodman's continuum ---------------------------------------------------------------

// Isotropic rock with joints at spacing s dipping 45 deg, k_n s and k_s s fixed, so that Goodman's TI medium
// (theory::goodman: 1/E' = 1/E + 1/(k_n s), 1/G' = 1/G + 1/(k_s s)) is the same for every s; two elements across a
// layer. The blocks cut by the free sides x = 0, W (a boundary layer about s wide) make the error fall with s / W;
// the sides along the strike (y = 0, depth) carry none, the medium's stress being uniaxial there too, so the prism
// is 12.5 mm deep (DISABLED_GoodmanConvergenceTable compares 50 mm).
TEST(FeJoints3, JointSetAt45TendsToGoodman) {
  const double E = 20e9, nu = 0.25, kns = 1.0 * E, kss = 0.4 * E;  // E' = E / 2, G' = G / 2
  std::vector<double> error;
  for (const double s : {0.025, 0.0125, 0.00833}) {
    const TetMesh& m = specimen(Shape3::prism, {45, 0, s, 0.0}, s / 2, false, {}, W / 4);
    const auto f = joint_interfaces(m, kns / s, kss / s);
    const JointedFe3Result r =
        solve_elastic_3d_jointed(m, same_for_all(m, TIConstants::isotropic(E, nu)), 45, 0, f);
    const theory::Uniaxial3 g = theory::amadei_uniaxial_3d(theory::goodman(E, nu, kns / s, kss / s, s), 45);
    error.push_back(std::abs(r.apparent_modulus / g.modulus - 1));
    std::printf("Goodman 45 deg  s/W %.3f  tets %6zu  DoFs %6zu  E_app %.5e  Goodman %.5e  error %.3e  nu_strike "
                "%.4f (%.4f)  nu_dip %.4f (%.4f)  %.2f s\n",
                s / W, m.num_tets(), r.dofs, r.apparent_modulus, g.modulus, error.back(), r.poisson_strike,
                g.poisson_strike, r.poisson_dip, g.poisson_dip, r.seconds);
  }
  for (std::size_t k = 1; k < error.size(); ++k) EXPECT_LT(error[k], error[k - 1]);
  EXPECT_LT(error.back(), 0.1);
}

// The convergence table of docs/continuum.md: isotropic rock (as JointSetAt45TendsToGoodman) and the layered TI
// rock with joints (theory::add_joints), k_n s = E', k_s s = 0.4 E', s / W down to 1/8; prisms 50 and 12.5 mm
// deep (the sides along the strike carry no error: the medium's stress is uniaxial there too), two and three
// elements across a layer. A s/V: the joint area per volume times s (1 for Goodman's medium).
TEST(FeJoints3, DISABLED_GoodmanConvergenceTable) {
  std::printf("rock       depth (mm)  elements/s  s/W    A s/V   tets    DoFs    E_app (GPa)  TI medium (GPa)  "
              "error      nu_strike (medium)  nu_dip (medium)   time (s)\n");
  for (const bool ti : {false, true})
    for (const double depth : {W, W / 4})
      for (const double per_layer : {2.0, 3.0, 4.0, 6.0})
        for (const double s : {0.025, 0.0125, 0.00833, 0.00625}) {
          // the mesh's size: more elements per layer only on the thin prism, and only at s / W = 1/4 beyond 3
          if (per_layer * W / s > (depth < W ? 24.5 : 16.5) || (per_layer > 3 && (depth == W || s != 0.0125)))
            continue;
          const TIConstants rock = ti ? layered : TIConstants::isotropic(20e9, 0.25);
          const double kn = rock.E_prime / s, ks = 0.4 * rock.E_prime / s;
          const TetMesh& m = specimen(Shape3::prism, {45, 0, s, 0.0}, s / per_layer, false, {}, depth);
          const JointedFe3Result r =
              solve_elastic_3d_jointed(m, same_for_all(m, rock), 45, 0, joint_interfaces(m, kn, ks));
          const theory::Uniaxial3 g = theory::amadei_uniaxial_3d(theory::add_joints(rock, kn, ks, s), 45);
          double area = 0;
          for (const SharedFace& f : shared_faces(m)) {
            if (!f.joint) continue;
            const auto &a = m.nodes[std::size_t(f.nodes[0])], &b = m.nodes[std::size_t(f.nodes[1])],
                       &c = m.nodes[std::size_t(f.nodes[2])];
            const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            area += 0.5 * std::sqrt(std::pow(u[1] * v[2] - u[2] * v[1], 2) + std::pow(u[2] * v[0] - u[0] * v[2], 2) +
                                    std::pow(u[0] * v[1] - u[1] * v[0], 2));
          }
          std::printf("%-9s  %10.1f  %10.0f  %.3f  %.4f  %6zu  %6zu  %11.4f  %15.4f  %9.2e  %.4f (%.4f)   "
                      "%.4f (%.4f)   %6.2f\n",
                      ti ? "TI" : "isotropic", depth * 1e3, per_layer, s / W, area * s / r.volume, m.num_tets(), r.dofs,
                      r.apparent_modulus / 1e9, g.modulus / 1e9, r.apparent_modulus / g.modulus - 1,
                      r.poisson_strike, g.poisson_strike, r.poisson_dip, g.poisson_dip, r.seconds);
        }
}

// ---- Stiff joints tend to the unjointed rock ---------------------------------------------------------------------

// Isotropic rock, k_n = k_s = f E / s: the joints' extra compliance is of order 1 / f of the rock's, so the modulus
// tends to the unjointed one as 1 / f (checked over two decades).
TEST(FeJoints3, StiffJointsTendToTheUnjointedSolution) {
  const double E = 20e9, nu = 0.25, s = 0.025;
  const auto rock = TIConstants::isotropic(E, nu);
  const TetMesh& m = specimen(Shape3::cylinder, {60, 0, s, 0.0}, 0.012);
  const double none = solve_elastic_3d(m, rock, 60, 0, direct()).apparent_modulus;
  std::vector<double> loss;
  for (const double factor : {1e1, 1e3, 1e5}) {
    const auto f = joint_interfaces(m, factor * E / s, factor * E / s);
    const JointedFe3Result r = solve_elastic_3d_jointed(m, same_for_all(m, rock), 60, 0, f, direct());
    loss.push_back(none / r.apparent_modulus - 1);
    std::printf("stiff joints k s / E = %.0e: E_none / E_app - 1 = %.4e\n", factor, loss.back());
    EXPECT_GT(loss.back(), 0.0);
    EXPECT_LT(loss.back(), 2 / factor);
  }
  for (std::size_t k = 1; k < loss.size(); ++k) EXPECT_NEAR(loss[k - 1] / loss[k], 100.0, 5.0);
}

// ---- Solvers and bad input ---------------------------------------------------------------------------------------

TEST(FeJoints3, CgAmgMatchesTheDirectSolver) {
  const TetMesh& m = specimen(Shape3::cylinder, {60, 0, 0.025, 0.0}, 0.012);
  const auto f = joint_interfaces(m, 20e9 / 0.025, 8e9 / 0.025);
  Fe3Options cg;
  cg.solver = Solver::cg_amg, cg.cg_tolerance = 1e-12;
  const auto layers = same_for_all(m, layered);
  const JointedFe3Result a = solve_elastic_3d_jointed(m, layers, 60, 0, f, direct());
  const JointedFe3Result b = solve_elastic_3d_jointed(m, layers, 60, 0, f, cg);
  EXPECT_EQ(a.solver_used, Solver::direct);
  EXPECT_EQ(b.solver_used, Solver::cg_amg);
  EXPECT_GT(b.iterations, 0u);
  EXPECT_NEAR(b.apparent_modulus / a.apparent_modulus, 1.0, 1e-9);
  EXPECT_NEAR(b.poisson_dip, a.poisson_dip, 1e-9);
}

// Each mistake a caller can make is refused with std::invalid_argument whose message names the input.
TEST(FeJoints3, RejectsBadInputNamingTheProblem) {
  const TetMesh& m = specimen(Shape3::prism, {0, 0, 0.5, 0.0}, 0.025);
  const auto layers = same_for_all(m, layered);
  const auto good = joint_interfaces(m, 1e12, 1e12);
  ASSERT_GT(good.size(), 1u);
  auto refused = [&](const std::vector<TIConstants>& c, const std::vector<InterfaceFace>& f, const Fe3Options& o,
                     const std::string& names) {
    try {
      solve_elastic_3d_jointed(m, c, 0, 0, f, o);
      ADD_FAILURE() << "accepted; expected a message naming " << names;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(names), std::string::npos) << e.what();
    }
  };
  Fe3Options p2;
  p2.degree = 2;
  refused(layers, good, p2, "degree");
  refused({layered}, good, {}, "layer_constants");
  refused(same_for_all(m, {1e9, 0.2, -1e9, 0.1, 1e9}), good, {}, "not admissible");
  auto twice = good;
  twice.push_back(good[0]);
  refused(layers, twice, {}, "list each interface face once");
  auto apart = good;
  apart[0].tet_b = apart[0].tet_a;
  refused(layers, apart, {}, "share no face");
  auto soft = good;
  soft[1].k_s = 0;
  refused(layers, soft, {}, "k_s = 0");
  auto half = good;
  half[1].k_n = inf;
  refused(layers, half, {}, "both infinite");
  auto outside = good;
  outside[0].tet_a = -1;
  refused(layers, outside, {}, "outside");
  EXPECT_THROW(solve_elastic_3d_jointed(TetMesh{}, {layered}, 0, 0, {}), std::invalid_argument);
  TetMesh stray = m;  // a node no tetrahedron uses, below the specimen: nothing stands on the bottom
  stray.nodes.push_back({0.0, 0.0, -0.01});
  try {
    solve_elastic_3d_jointed(stray, layers, 0, 0, good, direct());
    ADD_FAILURE() << "a mesh with nothing on its bottom was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("bottom"), std::string::npos) << e.what();
  }
  EXPECT_THROW(joint_interfaces(m, 1, 1, 2), std::invalid_argument);
}

// ---- Cost --------------------------------------------------------------------------------------------------------

// The costs of docs/continuum.md: the cylinder of scenes/cylinder.toml (60 deg, joints every 10 mm) at 4 and 3 mm,
// isotropic rock E = 40 GPa, nu = 0.2, with joints of k_n s = f E, k_s s = 0.4 f E (f = 1: as compliant as the
// rock; f = 0.1: ten times more), P1 with CG+AMG, beside the continuum (fe_3d, Goodman's medium) on the same mesh.
TEST(FeJoints3, DISABLED_CostTable) {
  std::printf("h (mm)  tets    nodes  joint faces  f     copies  DoFs    iter  setup (s)  assemble (s)  solve (s)  "
              "total (s)  E_app (GPa)  | continuum DoFs  iter  total (s)  E_app (GPa)\n");
  const double E = 40e9, nu = 0.2, s = 0.01;
  for (const double h : {0.004, 0.003})
    for (const double f : {1.0, 0.1}) {
      const TetMesh& m = specimen(Shape3::cylinder, {60, 0, s, 0.0}, h);
      const double kn = f * E / s, ks = 0.4 * kn;
      const auto joints = joint_interfaces(m, kn, ks);
      const JointedFe3Result r =
          solve_elastic_3d_jointed(m, same_for_all(m, TIConstants::isotropic(E, nu)), 60, 0, joints);
      const Fe3Result c = solve_elastic_3d(m, theory::goodman(E, nu, kn, ks, s), 60, 0);
      const double c_total = c.setup_seconds + c.assemble_seconds + c.solve_seconds + c.post_seconds;
      std::printf("%6.1f  %6zu  %5zu  %11zu  %4.1f  %6zu  %6zu  %4u  %9.2f  %12.2f  %9.2f  %9.2f  %11.4f  | %14zu  "
                  "%4u  %9.2f  %11.4f\n",
                  h * 1e3, m.num_tets(), m.num_nodes(), joints.size(), f, r.copies, r.dofs, r.iterations,
                  r.setup_seconds, r.assemble_seconds, r.solve_seconds, r.seconds, r.apparent_modulus / 1e9, c.dofs,
                  c.iterations, c_total, c.apparent_modulus / 1e9);
    }
}

}  // namespace
}  // namespace rbdem::continuum
