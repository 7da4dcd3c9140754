// rbdem cyclic and rbdem hold (dem/driver/protocols/cyclic.cpp, hold.cpp): the cycles of an elastic specimen
// against its static modulus, the loops' energy, failure after the cycles, the platen servo's response against its
// first-order law, a 10 MPa hold, and the scene checks of both tests.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numeric>

#include "dem/driver/driver.hpp"
#include "dem/driver/platen_test.hpp"
#include "dem/driver/registry.hpp"
#include "tests/simulations.hpp"

namespace rbdem {
namespace {

Scene small_scene() {
  Scene s;
  s.mesh.size = 0.004;
  s.numerics.threads = 1;
  return s;
}

// Bonds a hundred times stronger: the specimen stays linear elastic at the test's stresses.
Scene elastic_scene() {
  Scene s = small_scene();
  s.rock.tensile_strength *= 100, s.rock.cohesion *= 100, s.joint.tensile_strength *= 100, s.joint.cohesion *= 100;
  return s;
}

// A linear elastic specimen unloads and reloads along its loading line: both secant moduli of every cycle are the
// static modulus K H / A of the closure solve (TestResult "intact_modulus_pa"), up to the platen's dynamics, which a
// platen at 2.5 mm/s keeps below 1 % on branches of 3 MPa and more (at 10 mm/s the first cycle's moduli are 3 %
// off; on branches of 2 MPa at 2.5 mm/s, 1.4 %). No bond breaks, so the
// modulus does not fall, and each loop's net platen work is what local damping took: the stored energy is the same
// at the reversal and at the closure (both at the level's stress) up to the kinetic energy, which is small.
TEST(Cyclic, AnElasticSpecimenUnloadsAndReloadsAtItsStaticModulus) {
  Scene s = elastic_scene();
  s.loading.platen_velocity = 0.0025;
  s.loading.cycles = 2, s.loading.cycle_max_stress = 8e6, s.loading.cycle_unload_stress = 1e6;
  s.loading.cycle_to_failure = false;
  const auto t0 = std::chrono::steady_clock::now();
  const TestResult r = run_test("cyclic", s, make_mesh(s));
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(r.test, "cyclic");
  ASSERT_EQ(r.stop_reason, "cycles_done");
  ASSERT_EQ(r.cycles.size(), 2u);
  const double E0 = r.own_value("intact_modulus_pa");
  ASSERT_GT(E0, 0.0);
  for (const Cycle& c : r.cycles) {
    SCOPED_TRACE(c.cycle);
    EXPECT_DOUBLE_EQ(c.level, 4e6 * c.cycle);
    EXPECT_NEAR(c.unloading_modulus / E0, 1.0, 0.01);
    EXPECT_NEAR(c.reloading_modulus / E0, 1.0, 0.01);
    EXPECT_NEAR(c.strain_at_level * E0 / c.level, 1.0, 0.02);  // the reversal at the level, on the loading line
    EXPECT_LT(std::abs(c.modulus_loss), 0.01);
    EXPECT_EQ(c.cracks, 0);
    EXPECT_GE(c.dissipated, 0.0);
    EXPECT_NEAR(c.dissipated, c.damped, 0.15 * c.damped);
    EXPECT_LT(c.reversal_step, c.closure_step);
  }
  EXPECT_EQ(r.cracks.size(), 0u);
  EXPECT_NEAR(r.own_value("dissipated_total_j"), r.cycles[0].dissipated + r.cycles[1].dissipated, 1e-12);
  std::printf("cost: %ld steps, %.2f s wall\n", r.steps, wall);
}

// The weak specimen (joints at 60 deg) cycled below its strength, then loaded to failure: the cycles close, the
// post-peak criterion does not fire at an unloading, the run fails after the last cycle, the crack counts add up
// and every loop dissipates.
TEST(Cyclic, CyclesThenFailure) {
  Scene s = small_scene();
  s.loading.cycles = 3, s.loading.cycle_max_stress = 15e6, s.loading.cycle_unload_stress = 2e6;
  const TestResult r = run_test("cyclic", s, make_mesh(s));
  ASSERT_EQ(r.cycles.size(), 3u);
  EXPECT_EQ(r.stop_reason, "post_peak");
  EXPECT_GT(r.peak_stress, 15e6);
  int sum = 0;
  for (const Cycle& c : r.cycles) {
    sum += c.cracks;
    EXPECT_EQ(c.cracks_total, sum);
    EXPECT_GE(c.dissipated, 0.0);
    EXPECT_GT(c.unloading_modulus, 0.0);
    EXPECT_GT(c.reloading_modulus, 0.0);
  }
  EXPECT_GT(int(r.cracks.size()), r.cycles.back().cracks_total);  // the failure came after the cycles
}

TEST(Cyclic, RefusesAnUnloadStressAtTheFirstLevelAndAFastPlaten) {
  const ProtocolInfo& info = protocol_info("cyclic");
  Scene s = small_scene();
  s.loading.cycles = 4, s.loading.cycle_max_stress = 40e6, s.loading.cycle_unload_stress = 10e6;
  EXPECT_THROW(info.check(s), SceneError);
  s.loading.cycle_unload_stress = 1e6;
  EXPECT_NO_THROW(info.check(s));
  s.loading.fast_factor = 2;
  EXPECT_THROW(info.check(s), SceneError);
}

// The servo's law: where the specimen follows the platen quasi-statically, v = g (sigma* - sigma) and
// d sigma / dt = (K / A) v give sigma* - sigma = e0 exp(-t / tau), tau = A / (g K). Checked on an elastic specimen
// at rest at 9 MPa servoed to 10 MPa, at tau, 2 tau and 3 tau, to within 3 % of the first error (the specimen's
// lag behind the platen, about 1 / 10 of tau by the gain rule).
TEST(Hold, ServoErrorDecaysWithItsTimeConstant) {
  const Scene s = elastic_scene();
  const auto sim = fixtures::with_platens(s);
  sim->set_dt(0.6 * sim->stability_limit());
  StaticOptions so;
  so.platen_displacement = 1e-6 * sim->specimen().height();
  const StaticResult st = sim->solve_static(so);
  Platens& platens = *sim->find<Platens>();
  const double A = platens.area(), K = 0.5 * (st.top_force + st.bottom_force) / st.platen_displacement;
  const double factor = 9e6 * A / (0.5 * (st.top_force + st.bottom_force));
  sim->apply_static(StaticResult{}, st, factor, 0.0);
  platens.set_velocity(0.0);
  sim->step();  // the platen forces of the static state
  ASSERT_NEAR(platens.stress(), 9e6, 1e-3 * 9e6);
  const Specimen& sp = sim->specimen();
  const double M = std::accumulate(sp.blocks.mass.begin(), sp.blocks.mass.end(), 0.0);
  const double e0 = 10e6 - platens.stress();
  PlatenServo servo = hold_servo(K, M, A, 10e6, 1.0);
  servo.max_velocity = servo.gain * e0;  // never binding: the error only falls
  EXPECT_DOUBLE_EQ(servo.gain, A / (10.0 * std::sqrt(K * M)));
  platens.set_servo(servo);
  const double tau = A / (servo.gain * K);
  const long n_tau = std::lround(tau / sim->dt());
  ASSERT_GT(n_tau, 100);  // the explicit step is far below tau
  for (int k = 1; k <= 3; ++k) {
    for (long n = 0; n < n_tau; ++n) sim->step();
    EXPECT_NEAR((10e6 - platens.stress()) / e0, std::exp(-double(k)), 0.03) << k << " tau";
  }
}

// rbdem hold at 10 MPa for 10 000 steps: the platen closes at loading.platen_velocity to the target, the servo
// takes over and keeps the mean platen stress within 1 % over the whole hold (the worst deviation comes right after
// the switch, from the specimen's momentum), its mean within 0.1 %; the trace is in the curve.
TEST(Hold, ServoHoldsTenMegapascalsWithinOnePercent) {
  Scene s = small_scene();
  s.loading.hold_stress = 10e6, s.loading.hold_steps = 10000;
  const TestResult r = run_test("hold", s, make_mesh(s));
  ASSERT_EQ(r.test, "hold");
  EXPECT_EQ(r.stop_reason, "hold_done");
  EXPECT_EQ(r.own_value("hold_steps_held"), 10000.0);
  EXPECT_LT(r.own_value("hold_max_relative_deviation"), 0.01);
  EXPECT_NEAR(r.own_value("hold_mean_stress_pa"), 10e6, 1e-3 * 10e6);
  const long from = long(r.own_value("hold_start_step"));
  int samples = 0;
  for (const CurvePoint& p : r.curve)
    if (p.step > from) {
      ++samples;
      EXPECT_NEAR(p.stress(), 10e6, 0.01 * 10e6) << "step " << p.step;
    }
  EXPECT_GE(samples, 900);  // about 1000 samples over the hold
  std::printf("cost: %ld steps, %.2f s wall; worst deviation %.3f %%\n", r.steps, r.wall_seconds,
              100.0 * r.own_value("hold_max_relative_deviation"));
}

TEST(Hold, RefusesATargetAtOrBelowTheConfiningPressure) {
  const ProtocolInfo& info = protocol_info("hold");
  Scene s = small_scene();
  s.loading.confining_pressure = 10e6, s.loading.hold_stress = 5e6;
  EXPECT_THROW(info.check(s), SceneError);
  s.loading.hold_stress = 20e6;
  EXPECT_NO_THROW(info.check(s));
}

}  // namespace
}  // namespace rbdem
