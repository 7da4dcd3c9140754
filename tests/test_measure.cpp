// The stress inside the specimen (dem/measure.hpp): the Love-Weber average of the whole specimen is the platen
// stress (and the jacket's pressure) in a uniform elastic state, the regions partition it exactly, and bad regions
// are refused with a message naming them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "dem/measure.hpp"
#include "dem/specimen_mesh.hpp"
#include "tests/simulations.hpp"

namespace rbdem {
namespace {

Scene small_scene(double dip) {
  Scene scene;
  scene.mesh.size = 0.003, scene.joint_set.dip_deg = dip;
  scene.numerics.threads = 1;
  return scene;
}

// The static elastic state of a platen closure of 1e-6 of the height (with an optional load, e.g. a confining
// pressure), applied to the simulation; returns the mean platen stress of the solution (compression positive).
double elastic_start(Simulation& sim, const Scene& scene, std::vector<double> load = {}) {
  StaticOptions closure;
  closure.platen_displacement = 1e-6 * scene.specimen.height;
  closure.load = std::move(load);
  const StaticResult st = sim.solve_static(closure);
  sim.apply_static({}, st, 1.0, 0.0);
  return 0.5 * (st.top_force + st.bottom_force) / (scene.specimen.width * scene.specimen.thickness);
}

// Between frictionless platens the whole specimen's average stress is the platen stress: sigma_yy = -p (tension
// positive), sigma_xx = 0, at every joint dip. The blocks' forces between them cancel in pairs; what is left is the
// platens' loads times their lever arms, so this fails if a platen load is missing, misplaced or of the wrong sign.
TEST(Measure, WholeSpecimenStressIsThePlatenStress) {
  for (const double dip : {0.0, 45.0, 90.0}) {
    const Scene scene = small_scene(dip);
    const auto sim = fixtures::with_platens(scene);
    const double p = elastic_start(*sim, scene);
    ASSERT_GT(p, 0.0);
    const StressTensor s = average_stress(*sim);
    EXPECT_EQ(s.blocks, sim->num_blocks());
    EXPECT_NEAR(s.volume, scene.specimen.width * scene.specimen.height * scene.specimen.thickness, 1e-12);
    EXPECT_NEAR(s.yy() / -p, 1.0, 0.01) << "dip " << dip;
    EXPECT_LT(std::abs(s.xx()), 0.01 * p) << "dip " << dip;
    EXPECT_LT(std::abs(s.xy()), 0.01 * p) << "dip " << dip;
    std::printf("dip %4.0f: platen %.6g Pa, Love-Weber xx %.6g yy %.6g xy %.6g Pa, yy/-p - 1 = %.3e\n", dip, p,
                s.xx(), s.yy(), s.xy(), s.yy() / -p - 1);
    // Without the platens' loads the sum misses the stress the platens carry into the blocks they touch (their
    // lever arm is about a block's size, the missing share about the mesh size over the height, 3 mm / 100 mm).
    const StressTensor inner = average_stress(*sim, Region::whole(), {true, true, false});
    EXPECT_GT(inner.yy() / -p, 0.9) << "dip " << dip;
    EXPECT_LT(inner.yy() / -p, 0.995) << "dip " << dip;
  }
}

// In an explicit run the platens' loads are their contact forces at the state now: carried on from the static
// elastic start with the platen closing at the scene's speed (a quasi-static run, breakage off), the whole
// specimen's sigma_yy follows the platens' mean stress of the last step.
TEST(Measure, WholeSpecimenStressFollowsThePlatensInAnExplicitRun) {
  for (const double dip : {0.0, 45.0, 90.0}) {
    Scene scene = small_scene(dip);
    auto sim = std::make_unique<SimulationImpl<2>>(scene, make_mesh(scene));
    Platens& platens = sim->add_platens({scene.loading.platen_velocity, 0.0});
    sim->set_breakage(false);
    sim->set_dt(0.5 * sim->stability_limit());
    StaticOptions closure;
    closure.platen_displacement = 1e-6 * scene.specimen.height;
    sim->apply_static({}, sim->solve_static(closure), 1.0, scene.loading.platen_velocity);
    sim->run(2000);
    const double p = platens.stress();
    const StressTensor s = average_stress(*sim);
    std::printf("explicit, dip %4.0f: %ld steps, platens %.6g Pa, Love-Weber yy %.6g Pa, yy/-p - 1 = %.3e\n", dip,
                sim->steps(), p, s.yy(), s.yy() / -p - 1);
    EXPECT_NEAR(s.yy() / -p, 1.0, 0.01) << "dip " << dip;
  }
}

// A jacket's pressure enters the same way: under a confining pressure q and a platen closure, sigma_xx = -q.
TEST(Measure, WholeSpecimenStressHoldsTheJacketPressure) {
  const Scene scene = small_scene(30);
  const auto sim = fixtures::with_platens(scene);
  const double q = 1e6;
  sim->add_jacket(q);
  const double p = elastic_start(*sim, scene, sim->pressure_load(q));
  const StressTensor s = average_stress(*sim);
  EXPECT_NEAR(s.xx() / -q, 1.0, 0.01);
  EXPECT_NEAR(s.yy() / -p, 1.0, 0.01);
  std::printf("jacket %.6g Pa, platen %.6g Pa: Love-Weber xx %.6g yy %.6g xy %.6g Pa\n", q, p, s.xx(), s.yy(), s.xy());
}

// The stress per block and of the regions are the same sums split differently: the volume-weighted means of the
// blocks' stresses, of the layers' and of two halves of the specimen equal the whole specimen's, to round-off.
TEST(Measure, BlocksLayersAndHalvesPartitionTheWholeSpecimen) {
  const Scene scene = small_scene(60);
  const auto sim = fixtures::with_platens(scene);
  const double p = elastic_start(*sim, scene);
  const StressTensor whole = average_stress(*sim);
  const double tol = 1e-9 * p;

  const BlockStresses per_block = block_stresses(*sim);
  ASSERT_EQ(per_block.size(), sim->num_blocks());
  double sum[4] = {}, volume = 0;
  for (std::size_t b = 0; b < per_block.size(); ++b) {
    for (int c = 0; c < 4; ++c) sum[c] += per_block.volume[b] * per_block.stress[4 * b + std::size_t(c)];
    volume += per_block.volume[b];
  }
  EXPECT_NEAR(sum[0] / volume, whole.xx(), tol);
  EXPECT_NEAR(sum[3] / volume, whole.yy(), tol);
  EXPECT_NEAR(sum[1] / volume, whole.xy(), tol);
  EXPECT_EQ(sum[1], sum[2]);  // symmetric

  const std::vector<int>& layer = sim->specimen().blocks.layer;
  const int layers = *std::max_element(layer.begin(), layer.end()) + 1;
  ASSERT_GT(layers, 2);
  double yy = 0, v = 0;
  for (int l = 0; l < layers; ++l) {
    const StressTensor s = average_stress(*sim, Region::layers({l}));
    yy += s.yy() * s.volume, v += s.volume;
  }
  EXPECT_NEAR(yy / v, whole.yy(), tol);

  const Specimen& sp = sim->specimen();
  const double mid = 0.5 * (sp.lo[0] + sp.hi[0]);
  const StressTensor left = average_stress(*sim, Region::box({sp.lo[0] - 1, sp.lo[1] - 1}, {mid, sp.hi[1] + 1}));
  const StressTensor right = average_stress(*sim, Region::box({mid + 1e-12, sp.lo[1] - 1}, {sp.hi[0] + 1, sp.hi[1] + 1}));
  EXPECT_EQ(left.blocks + right.blocks, sim->num_blocks());
  EXPECT_NEAR((left.yy() * left.volume + right.yy() * right.volume) / (left.volume + right.volume), whole.yy(), tol);
}

// Inside the specimen the bonds and contacts alone give the stress: a circle in the middle of a specimen of
// horizontal layers between frictionless platens is under the uniform platen stress (to the discretisation's
// scatter, a few per cent), and Region::blocks of the circle's blocks gives the same numbers.
TEST(Measure, InteriorRegionFromBondsAndContacts) {
  const Scene scene = small_scene(0);
  const auto sim = fixtures::with_platens(scene);
  const double p = elastic_start(*sim, scene);
  const Specimen& sp = sim->specimen();
  const Region circle = Region::circle({0.5 * (sp.lo[0] + sp.hi[0]), 0.5 * (sp.lo[1] + sp.hi[1])}, 0.015);
  const StressTensor s = average_stress(*sim, circle, {true, true, false});
  EXPECT_NEAR(s.yy() / -p, 1.0, 0.03);
  EXPECT_LT(std::abs(s.xx()), 0.03 * p);
  const StressTensor all = average_stress(*sim, circle);  // no block of the circle touches a platen
  EXPECT_EQ(all.yy(), s.yy());
  const StressTensor listed = average_stress(*sim, Region::blocks(region_blocks(*sim, circle)), {true, true, false});
  EXPECT_EQ(listed.yy(), s.yy());
  EXPECT_EQ(listed.blocks, s.blocks);
  std::printf("interior circle (%zu blocks): yy/-p - 1 = %.3e, xx/p = %.3e\n", s.blocks, s.yy() / -p - 1, s.xx() / p);
}

// The stress of a static solution from its own forces (static_stress) against the engine's tables in the same
// state (average_stress after apply_static), over the interior circle of a specimen of horizontal layers between
// platens. As the laws run, the two must agree wherever the solve's linear-part states are the engine's (every
// bond but the few the active set may hold, StaticResult::held_bonds), to the terms of the displaced geometry
// (a 1e-6 strain, which the engine's laws see and the linearised forces do not): 1e-4 of the stress leaves room
// for both, and a wrong sign of the shear moves sigma_xx by half of sigma_yy. Held closed, every linear part is
// part of the linear model, and the circle carries the uniform platen stress.
TEST(Measure, StaticStressIsTheEngineStressWhereTheLinearPartsAgree) {
  const Scene scene = small_scene(0);
  const auto sim = fixtures::with_platens(scene);
  const Specimen& sp = sim->specimen();
  const Region circle = Region::circle({0.5 * (sp.lo[0] + sp.hi[0]), 0.5 * (sp.lo[1] + sp.hi[1])}, 0.015);
  StaticOptions closure;
  closure.platen_displacement = 1e-6 * scene.specimen.height;
  const StaticResult st = sim->solve_static(closure);
  ASSERT_GT(st.open_bonds, 0u);  // the check must see open linear parts
  const StressTensor own = static_stress(*sim, st, circle);
  sim->apply_static({}, st, 1.0, 0.0);
  const StressTensor engine = average_stress(*sim, circle, {true, true, false});
  const double scale = std::abs(engine.yy());
  EXPECT_EQ(own.blocks, engine.blocks);
  EXPECT_NEAR(own.xx(), engine.xx(), 1e-4 * scale);
  EXPECT_NEAR(own.yy(), engine.yy(), 1e-4 * scale);
  EXPECT_NEAR(own.xy(), engine.xy(), 1e-4 * scale);

  const auto linear = fixtures::with_platens(scene);
  closure.linear_parts_always_closed = true;
  const StaticResult closed = linear->solve_static(closure);
  EXPECT_EQ(closed.open_bonds, 0u);
  const StressTensor held = static_stress(*linear, closed, circle);
  const double p = 0.5 * (closed.top_force + closed.bottom_force) / (scene.specimen.width * scene.specimen.thickness);
  EXPECT_NEAR(held.yy() / -p, 1.0, 0.03);  // the uniform platen stress, as InteriorRegionFromBondsAndContacts
  std::printf("static vs engine: xx %.6g / %.6g, yy %.6g / %.6g Pa (%zu open); held closed yy/-p - 1 = %.3e\n",
              own.xx(), engine.xx(), own.yy(), engine.yy(), st.open_bonds, held.yy() / -p - 1);
  EXPECT_THROW(static_stress(*linear, StaticResult{}, circle), std::invalid_argument);
}

// Groups: a force group presses the top row of blocks down with F in all, a fixed group holds the bottom row. The
// fixed group's loads are its reactions now (a static state applied without a step has no last step): they sum to
// F, and the whole specimen's sigma_yy is -F over the area times the lever between the two rows over the height,
// which lies between the rows' extreme centroid heights.
TEST(Measure, GroupsReportTheirForceAndTheirReactionNow) {
  const Scene scene = small_scene(30);
  auto sim = std::make_unique<SimulationImpl<2>>(scene, make_mesh(scene));
  const Specimen& sp = sim->specimen();
  const double row = 0.6 * scene.mesh.size;
  std::vector<int> top, bottom;
  for (std::size_t b = 0; b < sp.num_blocks(); ++b) {
    const double y = sp.blocks.centroid[2 * b + 1];
    if (y > sp.hi[1] - row) top.push_back(int(b));
    if (y < sp.lo[1] + row) bottom.push_back(int(b));
  }
  ASSERT_GT(top.size(), 5u);
  const double F = 1e5;  // N
  GroupSettings press;
  press.name = "press", press.blocks = top, press.mode = GroupSettings::Mode::force;
  press.value = {0.0, -F / double(top.size()), 0.0};
  GroupSettings hold;
  hold.name = "hold", hold.blocks = bottom, hold.mode = GroupSettings::Mode::fixed;
  sim->add_group(press), sim->add_group(hold);
  StaticOptions o;
  o.platens = false;
  sim->apply_static({}, sim->solve_static(o), 1.0, 0.0);

  const BoundaryLoads loads = sim->boundary_loads();
  double reaction = 0, pressed = 0;
  for (std::size_t k = 0; k < loads.size(); ++k) (loads.component[k] == 1 ? reaction : pressed) += loads.force[2 * k + 1];
  EXPECT_NEAR(pressed, -F, 1e-9 * F);
  EXPECT_NEAR(reaction / F, 1.0, 1e-6);

  const auto heights = [&](const std::vector<int>& blocks) {
    double lo = 1e300, hi = -1e300;
    for (int b : blocks) lo = std::min(lo, sp.blocks.centroid[2 * std::size_t(b) + 1]),
                         hi = std::max(hi, sp.blocks.centroid[2 * std::size_t(b) + 1]);
    return std::pair{lo, hi};
  };
  const auto [top_lo, top_hi] = heights(top);
  const auto [bottom_lo, bottom_hi] = heights(bottom);
  const double H = scene.specimen.height, p = F / (scene.specimen.width * scene.specimen.thickness);
  const StressTensor s = average_stress(*sim);
  std::printf("groups: sigma_yy / (-F / A) = %.5f, lever bounds [%.5f, %.5f]\n", s.yy() / -p,
              (top_lo - bottom_hi) / H, (top_hi - bottom_lo) / H);
  EXPECT_GT(s.yy() / -p, (top_lo - bottom_hi) / H * (1 - 1e-6));
  EXPECT_LT(s.yy() / -p, (top_hi - bottom_lo) / H * (1 + 1e-6));
}

void expect_refused(const Simulation& sim, const Region& r, const std::string& words) {
  try {
    average_stress(sim, r);
    ADD_FAILURE() << "accepted " << r.describe();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}

TEST(Measure, BadRegionsAreRefusedByName) {
  const Scene scene = small_scene(0);
  const auto sim = fixtures::with_platens(scene);
  expect_refused(*sim, Region::box({0, 0, 0}, {1, 1, 1}), "2 coordinates");
  expect_refused(*sim, Region::box({1, 0}, {0, 1}), "lo must not exceed hi");
  expect_refused(*sim, Region::circle({0, 0}, -1), "radius > 0");
  expect_refused(*sim, Region::circle({10, 10}, 0.001), "holds no block");
  expect_refused(*sim, Region::layers({999}), "layer 999");
  expect_refused(*sim, Region::blocks({-1}), "block -1");
  expect_refused(*sim, Region::blocks({}), "holds no block");
}

}  // namespace
}  // namespace rbdem
