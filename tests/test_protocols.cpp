// The test protocols on the driver (dem/driver/protocols/, dem/driver/registry.hpp): confined compression's static
// isotropic start and its effect on the strength, the Brazilian test's tensile strength and failure classes, and the
// scene checks that keep a test from running on the wrong specimen.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "dem/driver/driver.hpp"
#include "dem/driver/monitors.hpp"
#include "dem/driver/platen_test.hpp"
#include "dem/driver/registry.hpp"
#include "tests/simulations.hpp"

namespace rbdem {
namespace {

Scene small_scene(double dip) {
  Scene s;
  s.mesh.size = 0.004;
  s.joint_set.dip_deg = dip;
  s.numerics.threads = 1;
  return s;
}

// loading.fast_factor (LoadRate, dem/driver/monitors.hpp), step by step against its rule: the platen keeps
// platen_velocity until quiet_transits wave transits T = H / sqrt(E*/rho) have passed without a break, then gains
// (f - 1) v dt / T per step up to f v; the step after a break it starts back and is at v within T / 4. The platen
// closes at 0.2 m/s so that bonds break within the test's 4 000 steps.
TEST(Loading, FastPlatenFollowsItsRuleBetweenBreaks) {
  Scene s = small_scene(90);
  s.loading.platen_velocity = 0.2, s.loading.fast_factor = 4, s.loading.quiet_transits = 1;
  const auto sim = fixtures::with_platens(s);
  sim->set_dt(0.5 * sim->stability_limit());
  const LoadRate rate(s);
  const double v = s.loading.platen_velocity, f = 4, dt = sim->dt();
  const double T = sim->specimen().height() / std::sqrt(s.rock.effective_modulus / s.rock.density);
  const double rise = (f - 1) * v * dt / T;
  std::vector<double> speed;
  std::vector<std::size_t> cracks;
  for (int n = 0; n < 4000; ++n) {
    sim->step();
    rate.after_step(*sim);
    speed.push_back(sim->find<Platens>()->velocity()), cracks.push_back(sim->cracks().size());
  }
  // Before the first break: v while t <= T, then the ramp, then f v.
  const auto first_break = std::size_t(std::find_if(cracks.begin(), cracks.end(), [](std::size_t c) { return c > 0; }) -
                                       cracks.begin());
  ASSERT_LT(first_break, speed.size()) << "no bond broke: the test needs a break";
  const auto quiet_end = std::size_t(T / dt);  // the first step past T (step n ends at t = (n + 1) dt)
  ASSERT_LT(quiet_end + std::size_t(T / dt) + 10, first_break) << "the platen must reach f v before the first break";
  for (std::size_t n = 0; n < first_break; ++n) {
    const double t = double(n + 1) * dt;
    const double expected = t <= T ? v : std::min(f * v, v + rise * double(n + 1 - quiet_end));
    ASSERT_NEAR(speed[n], expected, 1e-9 * v) << "step " << n;
  }
  EXPECT_DOUBLE_EQ(speed[first_break - 1], f * v);
  // After each break: falling from the step of the break on, at v within T / 4.
  const auto quarter = std::size_t(std::ceil(0.25 * T / dt));
  int fast_breaks = 0;
  for (std::size_t n = 1; n < speed.size(); ++n) {
    if (cracks[n] == cracks[n - 1]) continue;
    if (speed[n - 1] > v) {
      EXPECT_LT(speed[n], speed[n - 1]) << "break at step " << n;
      ++fast_breaks;
    }
    if (n + quarter < speed.size()) {
      EXPECT_EQ(speed[n + quarter], v) << "break at step " << n;
    }
  }
  EXPECT_GT(fast_breaks, 0) << "no break came while the platen was fast";
}

// loading.max_strain holds with a faster platen too: a specimen too strong to break runs fast to max_strain and
// stops there, within one step, not where the step count of the constant speed would end.
TEST(Loading, FastPlatenStopsAtMaxStrain) {
  Scene s = small_scene(90);
  s.rock.tensile_strength *= 100, s.rock.cohesion *= 100, s.joint.tensile_strength *= 100, s.joint.cohesion *= 100;
  s.loading.fast_factor = 4, s.loading.quiet_transits = 1, s.loading.max_strain = 2e-4;
  const TestResult r = run_test("ucs", s, make_mesh(s));
  ASSERT_TRUE(r.completed);
  EXPECT_EQ(r.crack_counts.total(), 0);
  EXPECT_EQ(r.stop_reason, "max_strain");
  const double last = r.frames.back().strain, step = 4 * s.loading.platen_velocity * r.dt / s.specimen.height;
  EXPECT_GE(last, s.loading.max_strain - step);
  EXPECT_LE(last, s.loading.max_strain + step);
}

// loading.transit_strain_fraction: the platen speed follows the rock, v = f eps_s sqrt(E_s / rho) from the static
// start's strain and stress increments (its last curve point), and the run's summary reports it.
TEST(Loading, TransitFractionSetsThePlatenSpeedFromTheElasticStart) {
  Scene s = small_scene(90);
  s.loading.transit_strain_fraction = 0.0075;
  const TestResult r = run_test("ucs", s, make_mesh(s));
  ASSERT_TRUE(r.completed);
  const CurvePoint* last_static = nullptr;
  for (const auto& p : r.curve)
    if (p.step == -1) last_static = &p;
  ASSERT_NE(last_static, nullptr);
  const double eps = last_static->strain, sigma = last_static->stress();
  const double expected = 0.0075 * std::sqrt(eps * sigma / (s.rock.density * s.numerics.mass_scaling));
  EXPECT_NEAR(r.platen_velocity, expected, 1e-9 * expected);
  // The explicit run closes at that speed: strain per step v dt / H between two samples after the start.
  const CurvePoint& a = r.curve[std::size_t(std::find_if(r.curve.begin(), r.curve.end(),
                                                         [](const CurvePoint& p) { return p.step > 0; }) -
                                            r.curve.begin())];
  const CurvePoint& b = r.curve[r.curve.size() / 2 + r.curve.size() / 4];
  ASSERT_GT(b.step, a.step);
  EXPECT_NEAR((b.strain - a.strain) / double(b.step - a.step), expected * r.dt / s.specimen.height, 1e-9 * expected);
  EXPECT_TRUE(r.quasi_static) << r.quasi_static_reason;
}

// The point of following the rock: at a fixed platen speed a rock ten times softer (same strengths) needs more
// steps to reach its larger failure strain (the explicit part's strain grows as 1 / E and the time step shrinks as
// 1 / sqrt(E)); with the speed set by the transit fraction it needs about as many as the stiff one, and stays
// quasi-static.
TEST(Loading, TransitFractionKeepsTheStepsOfASofterRock) {
  auto steps = [](double modulus_factor, double fraction) {
    Scene s = small_scene(90);
    s.rock.effective_modulus *= modulus_factor, s.joint.effective_modulus *= modulus_factor;
    s.loading.transit_strain_fraction = fraction;
    const TestResult r = run_test("ucs", s, make_mesh(s));
    EXPECT_TRUE(r.completed && r.quasi_static) << r.quasi_static_reason;
    return double(r.steps);
  };
  const double fixed_ratio = steps(0.1, 0.0) / steps(1.0, 0.0);
  const double following_ratio = steps(0.1, 0.0075) / steps(1.0, 0.0075);
  EXPECT_GT(fixed_ratio, 1.5);  // 1.75 on this 4 mm mesh
  EXPECT_LT(following_ratio, 1.2);  // 1.005
  EXPECT_GT(following_ratio, 0.8);
}

// The static isotropic stage: the jacket's pressure and the platen closure superposed so that the platen stress is
// p. Handed to the explicit engine, the state is in equilibrium: both platens carry p W t and every block's net force
// is small against the pressure's force on one edge. The static solve is linear (loads on the reference geometry)
// and the engine is not (follower pressure on the displaced edges, co-rotated bonds), so the residual is of the order
// of the strain (p / E ~ 4e-5 here) times the edge force: the bound is 1e-3 of that force.
TEST(Triaxial, IsotropicStartIsInEquilibriumAtSigma1EqualsSigma3) {
  const Scene scene = small_scene(60);
  const auto sim = fixtures::with_platens(scene);
  Jacket& jacket = sim->add_jacket(0.0);
  const double p = 10e6;
  const StaticResult iso = isotropic_state(*sim, p);
  const double W = sim->specimen().width(), t = scene.specimen.thickness;
  EXPECT_NEAR(iso.top_force / (p * W * t), 1.0, 1e-9);
  EXPECT_NEAR(iso.bottom_force / (p * W * t), 1.0, 1e-6);
  StaticOptions closure;
  closure.platen_displacement = 1e-6 * sim->specimen().height();
  sim->apply_static(iso, sim->solve_static(closure), 0.0, scene.loading.platen_velocity);
  jacket.set_pressure(p);
  std::vector<double> fx, fy, m;
  sim->engine().evaluate_forces(fx, fy, m);
  double worst = 0;
  for (std::size_t b = 0; b < fx.size(); ++b) worst = std::max(worst, std::hypot(fx[b], fy[b]));
  EXPECT_LT(worst, 1e-3 * p * scene.mesh.size * t) << "largest out-of-balance force " << worst << " N";
  EXPECT_GT(sim->engine().state().contacts.size(), 0u);  // the platen candidates are listed
}

TEST(Triaxial, ConfinementRaisesTheStrengthAndTheSummaryReportsIt) {
  Scene scene = small_scene(90);
  const TriMesh mesh = make_mesh(scene);
  const TestResult ucs = run_test("triaxial", scene, mesh);
  scene.loading.confining_pressure = 10e6;
  const TestResult confined = run_test("triaxial", scene, mesh);
  EXPECT_EQ(confined.test, "triaxial");
  EXPECT_TRUE(confined.completed);
  EXPECT_EQ(confined.confining_pressure, 10e6);
  EXPECT_NEAR(confined.own_value("deviator_at_peak_pa"), confined.peak_stress - 10e6, 1e-6);
  EXPECT_GT(confined.peak_stress, ucs.peak_stress + 10e6);  // more than sigma_3 on top: the intact rock has friction
  EXPECT_GT(confined.own_value("isotropic_strain"), 0.0);
  EXPECT_LT(confined.own_value("isotropic_strain"), confined.strain_at_peak);
  EXPECT_EQ(confined.curve[1].stress_top, 0.1 * 10e6);  // the isotropic stage is on the curve
}

TEST(Brazilian, DiscSplitsAndReportsTheIsrmTensileStrength) {
  Scene scene = small_scene(0);
  scene.specimen.shape = "disc";
  scene.mesh.size = 0.003;
  scene.loading.platen_velocity = 0.002;
  const TestResult r = run_test("brazilian", scene, make_mesh(scene));
  ASSERT_TRUE(r.completed);
  EXPECT_EQ(r.stop_reason, "post_peak");
  const double tensile = r.own_value("tensile_strength_pa"), load = r.own_value("peak_load_n");
  EXPECT_NEAR(tensile, 2.0 * load / (std::numbers::pi * r.own_value("diameter_m") * scene.specimen.thickness),
              1e-9 * tensile);
  EXPECT_EQ(r.peak_stress, tensile);
  EXPECT_EQ(r.own_value("layer_angle_deg"), 90.0);
  // Layers across the load: the disc splits through the rock along the loaded diameter.
  EXPECT_EQ(r.failure_mode, "central_fracture");
  // Between the rock bonds' tensile strength and a tenth of it (a lattice of bonds fails in tension across the
  // diameter at a few tenths of the bond strength).
  EXPECT_LT(tensile, scene.rock.tensile_strength);
  EXPECT_GT(tensile, 0.1 * scene.rock.tensile_strength);
}

TEST(Protocols, ATestRefusesASpecimenItCannotLoad) {
  const auto check = [](const char* test, const Scene& s) { protocol_info(test).check(s); };
  Scene disc = small_scene(0);
  disc.specimen.shape = "disc";
  EXPECT_THROW(check("ucs", disc), SceneError);
  EXPECT_THROW(check("triaxial", disc), SceneError);
  Scene rect = small_scene(0);
  EXPECT_THROW(check("brazilian", rect), SceneError);
  rect.loading.confining_pressure = 1e6;
  EXPECT_THROW(check("ucs", rect), SceneError);
  EXPECT_NO_THROW(check("triaxial", rect));
  try {
    check("brazilian", small_scene(0));
    ADD_FAILURE() << "a rectangle was accepted for the Brazilian test";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("specimen.shape"), std::string::npos) << e.what();
  }
  EXPECT_THROW(protocol_info("ucss"), SceneError);  // an unknown test names the known ones
}

}  // namespace
}  // namespace rbdem
