// The stress inside the specimen (dem/measure.hpp): the Love-Weber average of the whole specimen is the platen
// stress (and the jacket's pressure) in a uniform elastic state, the regions partition it exactly, and bad regions
// are refused with a message naming them.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "dem/measure.hpp"
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
