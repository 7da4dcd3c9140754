// The state as tables (dem/state_tables.hpp): the bond and contact rows are the forces the engine sums into each
// block, the failure index is the law's (1 at the first break of a static path), and the signs follow the
// documented conventions.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "tests/simulations.hpp"

namespace rbdem {
namespace {

// A specimen past its first cracks (a fast platen breaks bonds within a few hundred steps): bonds, broken bonds
// and touching contacts all present.
std::unique_ptr<SimulationImpl<2>> cracked_specimen() {
  Scene scene;
  scene.mesh.size = 0.003, scene.joint_set.dip_deg = 45;
  scene.loading.platen_velocity = 0.5;
  scene.numerics.threads = 1;
  auto sim = fixtures::with_platens(scene);
  sim->set_dt(0.5 * sim->stability_limit());
  for (int k = 0; k < 80 && (sim->cracks().size() < 10 || sim->contact_states().size() < 20); ++k) sim->run(100);
  return sim;
}

// Each block away from the platens: the sum of its bond rows (-force on i, +force on j), its contact rows and
// their moments equals the engine's force evaluation in the same state, to round-off.
TEST(Tables, BondAndContactRowsSumToEachBlocksForce) {
  const auto sim = cracked_specimen();
  const BondStates bonds = sim->bond_states();
  const ContactStates contacts = sim->contact_states();
  const BlockStates blocks = sim->block_states();
  ASSERT_GT(sim->cracks().size(), 0u);
  ASSERT_GE(contacts.size(), 20u) << "the specimen has too few contacts to check them";
  const std::size_t n = blocks.size();
  std::vector<double> fx(n, 0.0), fy(n, 0.0), m(n, 0.0), scale(n, 0.0);
  const auto add = [&](int b, double px, double py, double gx, double gy, double couple) {
    const std::size_t k = std::size_t(b);
    fx[k] += gx, fy[k] += gy;
    m[k] += (px - blocks.position[2 * k]) * gy - (py - blocks.position[2 * k + 1]) * gx + couple;
    scale[k] = std::max(scale[k], std::hypot(gx, gy));
  };
  const Specimen& spec = sim->specimen();
  for (std::size_t b = 0; b < bonds.size(); ++b) {
    const double px = bonds.point[2 * b], py = bonds.point[2 * b + 1], gx = bonds.force[2 * b], gy = bonds.force[2 * b + 1];
    add(spec.bonds.j[b], px, py, gx, gy, bonds.moment[b]);
    add(spec.bonds.i[b], px, py, -gx, -gy, -bonds.moment[b]);
  }
  for (std::size_t c = 0; c < contacts.size(); ++c) {
    const double px = contacts.point[2 * c], py = contacts.point[2 * c + 1];
    add(contacts.j[c], px, py, contacts.force[2 * c], contacts.force[2 * c + 1], 0.0);
    add(contacts.i[c], px, py, -contacts.force[2 * c], -contacts.force[2 * c + 1], 0.0);
  }
  std::vector<double> ex, ey, em;
  sim->engine().evaluate_forces(ex, ey, em);
  const double margin = 3 * sim->engine().model().radius[0] + 0.002;
  int checked = 0;
  for (std::size_t b = 0; b < n; ++b) {
    const double y = blocks.position[2 * b + 1];
    if (y < spec.lo[1] + margin || y > spec.hi[1] - margin) continue;  // the platens' forces are not in the tables
    const double tol = 1e-9 * std::max(scale[b], 1.0);
    ASSERT_NEAR(fx[b], ex[b], tol) << "block " << b;
    ASSERT_NEAR(fy[b], ey[b], tol) << "block " << b;
    ASSERT_NEAR(m[b], em[b], tol * 0.01) << "block " << b;
    ++checked;
  }
  EXPECT_GT(checked, int(n) / 2);
}

// Brought statically to the first break of a platen closure, the bond that breaks first has failure index 1 and
// no bond more; the bonds across the loading direction are in compression (negative normal force).
TEST(Tables, FailureIndexIsOneAtTheFirstBreakAndCompressionIsNegative) {
  Scene scene;
  scene.mesh.size = 0.003, scene.joint_set.dip_deg = 90;
  scene.numerics.threads = 1;
  const auto sim = fixtures::with_platens(scene);
  StaticOptions closure;
  closure.platen_displacement = 1e-6 * sim->specimen().height();
  const StaticResult path = sim->solve_static(closure);
  int first = -1;
  const double lambda = sim->first_break_along({}, path, &first);
  ASSERT_GE(first, 0);
  sim->apply_static({}, path, lambda, 0.0);
  const BondStates bonds = sim->bond_states();
  // The static solve is linear, the bond evaluation co-rotated: they agree to the order of the strain (1e-4).
  EXPECT_NEAR(bonds.failure_index[std::size_t(first)], 1.0, 2e-3);
  double worst = 0, compressed = 0;
  int vertical = 0;
  for (std::size_t b = 0; b < bonds.size(); ++b) {
    worst = std::max(worst, bonds.failure_index[b]);
    if (std::abs(bonds.normal[2 * b + 1]) > 0.95) compressed += bonds.normal_force[b] < 0 ? 1 : 0, ++vertical;
  }
  EXPECT_LT(worst, 1.0 + 2e-3);
  EXPECT_GT(compressed, 0.95 * vertical) << "bonds across the load should be in compression";
  EXPECT_EQ(bonds.damage[std::size_t(first)], 0.0);
  EXPECT_EQ(sim->block_states().position.size(), 2 * sim->num_blocks());
}

}  // namespace
}  // namespace rbdem
