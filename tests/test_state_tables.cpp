// The state as tables (dem/state_tables.hpp): the bond and contact rows are the forces the engine sums into each
// block, the failure index is the law's (1 at the first break of a static path), and the signs follow the
// documented conventions.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "dem/measure.hpp"
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

// The tables, the energies and the force network that the driver takes between steps are computed on the run's
// threads above 4096 rows: on a specimen past its first cracks they are the same bits on one thread and on two
// (the two runs reach the same state), the network's rows are the intact bonds in order then the contacts, and the
// kinetic energy is the sum over the blocks in block order.
TEST(Tables, BetweenStepTablesAreTheSameOnOneAndTwoThreads) {
  const auto cracked = [](int threads) {
    Scene scene;
    scene.mesh.size = 0.0016, scene.joint_set.dip_deg = 45;
    scene.loading.platen_velocity = 1.0;
    scene.numerics.threads = threads;
    auto sim = fixtures::with_platens(scene);
    sim->set_dt(0.5 * sim->stability_limit(60));
    for (int k = 0; k < 40 && sim->cracks().size() < 10; ++k) sim->run(100);
    return sim;
  };
  const auto one = cracked(1), two = cracked(2);
  ASSERT_GT(one->specimen().num_bonds(), 4096u) << "the specimen must be large enough for the threaded paths";
  ASSERT_GT(one->cracks().size(), 0u);
  const Energies e1 = one->energies(), e2 = two->energies();
  EXPECT_EQ(e1.kinetic, e2.kinetic);
  EXPECT_EQ(e1.strain, e2.strain);
  const ModelState<2>& s = one->engine().state();
  const Model<2>& m = one->engine().model();
  double kinetic = 0;
  for (std::size_t b = 0; b < m.num_blocks(); ++b)
    kinetic += 0.5 * (m.mass[b] * (s.vx[b] * s.vx[b] + s.vy[b] * s.vy[b]) + m.inertia[b] * s.omega[b] * s.omega[b]);
  EXPECT_EQ(e1.kinetic, kinetic);
  const ContactStates c1 = one->contact_states(), c2 = two->contact_states();
  ASSERT_GT(c1.size(), 0u);
  EXPECT_EQ(c1.i, c2.i);
  EXPECT_EQ(c1.point, c2.point);
  EXPECT_EQ(c1.force, c2.force);
  EXPECT_EQ(c1.shear_force, c2.shear_force);
  const ForceNetwork n1 = force_network(*one), n2 = force_network(*two);
  EXPECT_EQ(n1.i, n2.i);
  EXPECT_EQ(n1.force, n2.force);
  EXPECT_EQ(n1.normal_force, n2.normal_force);
  const BondStates bonds = one->bond_states();
  const Specimen& sp = one->specimen();
  std::size_t row = 0;
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    if (!bonds.intact[k]) continue;
    ASSERT_EQ(n1.i[row], sp.bonds.i[k]);
    ASSERT_EQ(n1.kind[row], 0);
    ASSERT_EQ(n1.force[2 * row + 1], float(bonds.force[2 * k + 1]));
    ++row;
  }
  ASSERT_EQ(n1.size(), row + c1.size());
  for (std::size_t k = 0; k < c1.size(); ++k) {
    ASSERT_EQ(n1.j[row + k], c1.j[k]);
    ASSERT_EQ(n1.normal_force[row + k], float(-c1.normal_force[k]));
  }
  EXPECT_EQ(one->non_finite(), "");
}

}  // namespace
}  // namespace rbdem
