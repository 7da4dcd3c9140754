// Block groups moved each degree of freedom its own way (GroupSettings::modes): a prescribed velocity, a servo to a
// load with and without a spring in series (a shear box under constant normal load or constant normal stiffness),
// free under a load, held; against the closed forms of one bonded pair, and through a snapshot and a restore.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "compare/verify/specimens.hpp"
#include "dem/topology.hpp"
#include "tests/simulations.hpp"

namespace rbdem {
namespace {

using Mode = GroupSettings::Mode;

// The rhombus of two triangles bonded on their shared edge (-a, 0)-(a, 0), a joint bond: block 0 below in a fixed
// group, block 1 above in a group that moves along x at `v`, under a servo along y to the load -fn (pushing it down)
// with a spring `ks` in series, and held from turning.
struct Pair {
  static constexpr double a = 1e-3, b = 0.8e-3;
  Scene scene;
  std::unique_ptr<SimulationImpl<2>> sim;
  BlockGroup* box = nullptr;
  BlockGroup* base = nullptr;

  Pair(double v, double fn, double ks) {
    scene = verify::elastic_scene();
    scene.numerics.damping = 0.7;
    scene.numerics.threads = 1;
    const Topology<2> topo = build_topology(verify::rhombus(a, b, 0, 1), 1.0, 2700.0);
    sim = std::make_unique<SimulationImpl<2>>(scene, topo);
    base = &sim->add_group({"base", {0}, Mode::fixed, {}, {}, {}});
    GroupSettings g{"box", {1}, Mode::fixed, {v, -fn, 0.0}, {Mode::velocity, Mode::servo, Mode::fixed}, {1, 1, 0, 0}};
    box = &sim->add_group(g);
    // Every block is in a group, so no block's dynamics bounds the step: a 400th of the pair's period.
    sim->set_dt(2.0 * std::numbers::pi * std::sqrt(sim->engine().model().mass[1] / normal_stiffness()) / 400.0);
    // The servo from the pair's stiffness, as rbdem shear chooses it: a quarter of the load error per step.
    const double k = box->attachment_stiffness()[1] + ks;
    box->set_servo({0.25 / (k * sim->dt()), 1.0, ks, 0.0});
  }
  // The bond's normal stiffness: the parallel bond and the linear part, each E* / d on the area L t (d = 2 b / 3).
  double normal_stiffness() const { return 2.0 * scene.joint.effective_modulus / (2.0 * b / 3.0) * (2.0 * a); }
  void run(int steps) {
    for (int k = 0; k < steps; ++k) sim->step();
  }
};

// A servo with no spring comes to rest where the bond carries the load: u = -F / K.
TEST(BlockGroupModes, ServoSettlesWhereTheBondCarriesTheLoad) {
  const double fn = 2e4;
  Pair p(0.0, fn, 0.0);
  EXPECT_NEAR(p.box->attachment_stiffness()[1] / p.normal_stiffness(), 1.0, 1e-12);
  p.run(3000);
  EXPECT_NEAR(p.box->force()[1] / fn, 1.0, 1e-6);
  EXPECT_NEAR(p.box->displacement()[1] / (-fn / p.normal_stiffness()), 1.0, 1e-6);
  EXPECT_NEAR(p.base->force()[1] / -fn, 1.0, 1e-6);
  EXPECT_EQ(p.sim->engine().state().theta[1], 0.0);  // held from turning
  // At rest: a step moves it by under 1e-9 of its displacement.
  EXPECT_LT(std::abs(p.box->velocity()[1]) * p.sim->dt(), 1e-9 * std::abs(p.box->displacement()[1]));
}

// A spring ks in series (constant normal stiffness): the load falls by ks per metre the box moves towards the base,
// so it rests at u = -F0 / (K + ks), carrying F0 K / (K + ks).
TEST(BlockGroupModes, ServoWithASpringRestsWhereTheSpringAndTheBondBalance) {
  const double fn = 2e4;
  Pair probe(0.0, fn, 0.0);
  const double K = probe.normal_stiffness(), ks = 0.5 * K;
  Pair p(0.0, fn, ks);
  p.run(3000);
  EXPECT_NEAR(p.box->displacement()[1] / (-fn / (K + ks)), 1.0, 1e-6);
  EXPECT_NEAR(p.box->force()[1] / (fn * K / (K + ks)), 1.0, 1e-6);
}

// Along x the box moves at exactly its velocity while the servo holds the normal load; the bond resists with its
// shear stiffness K / kappa, the force the base takes too; the work is the integral of the reaction's power.
TEST(BlockGroupModes, PrescribedDofMovesAtItsVelocityWhileTheServoHoldsTheLoad) {
  const double fn = 2e4, v = 1e-3;
  Pair p(0.0, fn, 0.0);
  p.run(3000);
  const double w0 = p.box->work();
  p.box->set_value({v, -fn, 0.0});
  const int n = 2000;
  p.run(n);
  const double ux = p.box->displacement()[0], expected = v * n * p.sim->dt();
  EXPECT_NEAR(ux / expected, 1.0, 1e-12);
  const double kshear = p.normal_stiffness() / p.scene.joint.stiffness_ratio;
  EXPECT_NEAR(-p.box->force()[0] / (kshear * ux), 1.0, 1e-3);
  EXPECT_NEAR(p.base->force()[0] / (kshear * ux), 1.0, 1e-3);
  EXPECT_NEAR(p.box->force()[1] / fn, 1.0, 1e-4);
  EXPECT_EQ(p.box->velocity()[0], v);
  // The work of the shear: 1/2 K/kappa u^2 (the servo's share is second order here).
  EXPECT_NEAR((p.box->work() - w0) / (0.5 * kshear * ux * ux), 1.0, 0.02);
  bool has_velocity = false;
  for (const auto& [key, value] : p.box->readings()) has_velocity |= key == "velocity_x_m_s" && value == v;
  EXPECT_TRUE(has_velocity);
}

// A snapshot keeps the servo (as set_servo changed it), the values and the last velocities: a restored run goes on
// bit for bit.
TEST(BlockGroupModes, SnapshotAndRestoreContinueBitForBit) {
  Pair p(1e-3, 2e4, 1e9);
  p.run(500);
  GroupServo changed = p.box->settings().servo;
  changed.origin = p.box->displacement()[1];
  p.box->set_servo(changed);
  p.run(10);
  const Snapshot snap = p.sim->snapshot();
  p.run(300);
  const std::vector<double> pose = p.sim->pose(), force = p.box->force();
  const double work = p.box->work();
  Pair q(1e-3, 2e4, 0.0);  // another servo: the snapshot's must replace it
  q.sim->set_dt(p.sim->dt());
  q.sim->restore(snap);
  EXPECT_EQ(q.box->settings().servo.origin, changed.origin);
  EXPECT_EQ(q.box->settings().servo.stiffness, 1e9);
  q.run(300);
  EXPECT_EQ(q.sim->pose(), pose);
  EXPECT_EQ(q.box->force(), force);
  EXPECT_EQ(q.box->work(), work);
}

// A free dof moves the group as one body under the bond and its load: undamped, it oscillates about u = -F / K at
// the period 2 pi sqrt(m / K) of the pair (m block 1's mass); damped, it comes to rest there. set_modes turns the
// servo dof free between steps.
TEST(BlockGroupModes, FreeDofOscillatesAtThePairsPeriodAndRestsUnderItsLoad) {
  const double fn = 2e4;
  for (double damping : {0.0, 0.7}) {
    SCOPED_TRACE(testing::Message() << "damping " << damping);
    Scene scene = verify::elastic_scene();
    scene.numerics.damping = damping;
    scene.numerics.threads = 1;
    const Topology<2> topo = build_topology(verify::rhombus(Pair::a, Pair::b, 0, 1), 1.0, 2700.0);
    SimulationImpl<2> sim(scene, topo);
    sim.add_group({"base", {0}, Mode::fixed, {}, {}, {}});
    BlockGroup& box = sim.add_group({"box", {1}, Mode::fixed, {0.0, -fn, 0.0}, {Mode::fixed, Mode::servo, Mode::fixed},
                                     {1, 1, 0, 0}});
    box.set_modes({Mode::fixed, Mode::free, Mode::fixed});
    EXPECT_EQ(box.mode(1), Mode::free);
    // Every block is in a group, so the engine's stability limit sees no free block: the step resolves the period.
    const double K = 2.0 * scene.joint.effective_modulus / (2.0 * Pair::b / 3.0) * (2.0 * Pair::a);
    const double m = sim.engine().model().mass[1];
    const double period = 2.0 * std::numbers::pi * std::sqrt(m / K), dt = period / 400.0;
    sim.set_dt(dt);
    if (damping == 0.0) {
      // Released from rest under the load: u(t) = -F/K (1 - cos(omega t)); its first minimum at half a period.
      double u_min = 0, t_min = 0;
      for (int k = 1; k * dt < 0.75 * period; ++k) {
        sim.step();
        if (box.displacement()[1] < u_min) u_min = box.displacement()[1], t_min = k * dt;
      }
      EXPECT_NEAR(u_min / (-2.0 * fn / K), 1.0, 0.01);
      EXPECT_NEAR(t_min / (0.5 * period), 1.0, 0.02);
    } else {
      for (int k = 0; k < 4000; ++k) sim.step();
      EXPECT_NEAR(box.displacement()[1] / (-fn / K), 1.0, 1e-6);
      EXPECT_NEAR(box.force()[1] / fn, 1.0, 1e-6);
    }
  }
}

// Settings a group cannot follow are refused with what to give.
TEST(BlockGroupModes, RefusesModesItCannotFollow) {
  Pair p(0.0, 1.0, 0.0);
  const auto add = [&p](GroupSettings g) { p.sim->add_group(g); };
  EXPECT_THROW(add({"two", {0}, Mode::fixed, {0, 0, 0}, {Mode::velocity, Mode::servo}, {1, 1, 0, 0}}),
               std::invalid_argument);
  EXPECT_THROW(add({"mixed", {0}, Mode::fixed, {0, 0, 0}, {Mode::force, Mode::fixed, Mode::fixed}, {}}),
               std::invalid_argument);
  EXPECT_THROW(add({"no_gain", {0}, Mode::fixed, {0, 0, 0}, {Mode::fixed, Mode::servo, Mode::fixed}, {}}),
               std::invalid_argument);
  EXPECT_THROW(add({"no_values", {0}, Mode::fixed, {}, {Mode::velocity, Mode::fixed, Mode::fixed}, {}}),
               std::invalid_argument);
  EXPECT_THROW(p.box->set_servo({0.0, 1.0, 0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(p.box->set_modes({Mode::force, Mode::force, Mode::force}), std::invalid_argument);
}

}  // namespace
}  // namespace rbdem
