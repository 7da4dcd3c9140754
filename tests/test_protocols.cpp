// The test protocols on the driver (dem/driver/ucs.hpp): confined compression's static isotropic start and its
// effect on the strength, the Brazilian test's tensile strength and failure classes, and the scene checks that keep
// a test from running on the wrong specimen.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "dem/driver/ucs.hpp"
#include "dem/engine.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/static_solve.hpp"
#include "dem/topology.hpp"

namespace rbdem {
namespace {

Scene small_scene(double dip) {
  Scene s;
  s.mesh.size = 0.004;
  s.joint_set.dip_deg = dip;
  s.numerics.threads = 1;
  return s;
}

// The static isotropic stage: the jacket's pressure and the platen closure superposed so that the platen stress is
// p. Handed to the explicit engine, the state is in equilibrium: both platens carry p W t and every block's net force
// is small against the pressure's force on one edge. The static solve is linear (loads on the reference geometry)
// and the engine is not (follower pressure on the displaced edges, co-rotated bonds), so the residual is of the order
// of the strain (p / E ~ 4e-5 here) times the edge force: the bound is 1e-3 of that force.
TEST(Triaxial, IsotropicStartIsInEquilibriumAtSigma1EqualsSigma3) {
  const Scene scene = small_scene(60);
  const Topology topo = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  Engine e(topo, scene, EngineOptions::from_scene(scene));
  const double p = 10e6;
  const StaticResult iso = TriaxialProtocol::isotropic_state(e, p);
  const double W = topo.width(), t = scene.specimen.thickness;
  EXPECT_NEAR(iso.top_force / (p * W * t), 1.0, 1e-9);
  EXPECT_NEAR(iso.bottom_force / (p * W * t), 1.0, 1e-6);
  StaticOptions closure;
  closure.platen_displacement = 1e-6 * topo.height();
  apply_static_path(e, iso, solve_static(e, closure), 0.0, scene.loading.platen_velocity);
  e.set_confining_pressure(p);
  std::vector<double> fx, fy, m;
  e.evaluate_forces(fx, fy, m);
  double worst = 0;
  for (std::size_t b = 0; b < fx.size(); ++b) worst = std::max(worst, std::hypot(fx[b], fy[b]));
  EXPECT_LT(worst, 1e-3 * p * scene.mesh.size * t) << "largest out-of-balance force " << worst << " N";
  EXPECT_GT(e.state().contacts.size(), 0u);  // the platen candidates are listed
}

TEST(Triaxial, ConfinementRaisesTheStrengthAndTheSummaryReportsIt) {
  Scene scene = small_scene(90);
  const Topology topo = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  const TestResult ucs = run_test("triaxial", scene, topo);
  scene.loading.confining_pressure = 10e6;
  const TestResult confined = run_test("triaxial", scene, topo);
  EXPECT_EQ(confined.test, "triaxial");
  EXPECT_TRUE(confined.completed);
  EXPECT_EQ(confined.confining_pressure, 10e6);
  EXPECT_NEAR(confined.deviator_at_peak, confined.peak_stress - 10e6, 1e-6);
  EXPECT_GT(confined.peak_stress, ucs.peak_stress + 10e6);  // more than sigma_3 on top: the intact rock has friction
  EXPECT_GT(confined.isotropic_strain, 0.0);
  EXPECT_LT(confined.isotropic_strain, confined.strain_at_peak);
  EXPECT_EQ(confined.curve[1].stress_top, 0.1 * 10e6);  // the isotropic stage is on the curve
}

TEST(Brazilian, DiscSplitsAndReportsTheIsrmTensileStrength) {
  Scene scene = small_scene(0);
  scene.specimen.shape = "disc";
  scene.mesh.size = 0.003;
  scene.loading.platen_velocity = 0.002;
  const Topology topo = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  const TestResult r = run_test("brazilian", scene, topo);
  ASSERT_TRUE(r.completed);
  EXPECT_EQ(r.stop_reason, "post_peak");
  EXPECT_NEAR(r.tensile_strength, 2.0 * r.peak_load / (std::numbers::pi * r.diameter * scene.specimen.thickness),
              1e-9 * r.tensile_strength);
  EXPECT_EQ(r.peak_stress, r.tensile_strength);
  EXPECT_EQ(r.layer_angle_deg, 90.0);
  // Layers across the load: the disc splits through the rock along the loaded diameter.
  EXPECT_EQ(r.failure_mode, "central_fracture");
  // Between the rock bonds' tensile strength and a tenth of it (a lattice of bonds fails in tension across the
  // diameter at a few tenths of the bond strength).
  EXPECT_LT(r.tensile_strength, scene.rock.tensile_strength);
  EXPECT_GT(r.tensile_strength, 0.1 * scene.rock.tensile_strength);
}

TEST(Protocols, ATestRefusesASpecimenItCannotLoad) {
  Scene disc = small_scene(0);
  disc.specimen.shape = "disc";
  EXPECT_THROW(check_test_scene("ucs", disc), SceneError);
  EXPECT_THROW(check_test_scene("triaxial", disc), SceneError);
  Scene rect = small_scene(0);
  EXPECT_THROW(check_test_scene("brazilian", rect), SceneError);
  rect.loading.confining_pressure = 1e6;
  EXPECT_THROW(check_test_scene("ucs", rect), SceneError);
  EXPECT_NO_THROW(check_test_scene("triaxial", rect));
  try {
    check_test_scene("brazilian", small_scene(0));
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("specimen.shape"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rbdem
