// The explicit engine against closed forms: objectivity, oscillation frequency, energy in impact, Coulomb
// sliding, the bond-to-contact hand-over, and numerical stability at and above the computed time step.
#include <gtest/gtest.h>

#include <omp.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numbers>
#include <thread>

#include "compare/verify/dem_measures.hpp"
#include "compare/verify/specimens.hpp"
#include "dem/driver/driver.hpp"
#include "dem/stages/bond_kernel.hpp"
#include "dem/topology.hpp"
#include "tests/simulations.hpp"

namespace rbdem {
namespace {

using verify::elastic_scene;
using verify::rhombus;

// Free blocks: an engine with no boundary components attached, on one thread.
EngineOptions free_blocks(const Scene& s) {
  EngineOptions o = EngineOptions::from_scene(s);
  o.threads = 1;
  return o;
}

// The experiments are the ones `rbdem verify` reports (compare/verify/dem_measures.hpp); here with the unit tests'
// own acceptance limits.
TEST(Engine, RigidTranslationAndRotationCreateNoForce) {
  const verify::RigidMotionMeasure m = verify::rigid_motion_forces();
  // A strain of 1e-6 would give forces of order E* L t 1e-6 = 1e5 N here; round-off of 1 rad rotations is ~1e-16.
  EXPECT_LT(m.max_force, 1e-3);
  EXPECT_EQ(m.cracks, 0u);
}

// Period of block 1 against a fixed block 0, preloaded into compression so the linear part stays closed:
// stiffness (kb_n + k_n) A, omega = sqrt(k / m).
TEST(Engine, BondedPairOscillatesAtSqrtKOverM) {
  const verify::PairPeriodMeasure m = verify::bonded_pair_period(2000);
  EXPECT_NEAR(m.period / m.expected, 1.0, 0.01);
  EXPECT_NEAR(m.max_sideways, 0.0, 1e-12);  // symmetric: no sideways motion
}

// Two separate blocks (no bond) meet face to face and bounce apart: no damping, no friction.
TEST(Engine, FrictionlessElasticImpactConservesEnergy) {
  for (double angle_deg : {0.0, 20.0}) {
    const verify::ImpactMeasure m = verify::frictionless_impact(angle_deg);
    ASSERT_TRUE(m.touched) << "impact angle " << angle_deg;
    EXPECT_TRUE(m.separated) << "impact angle " << angle_deg;
    EXPECT_NEAR(m.energy_ratio, 1.0, 0.005) << "impact angle " << angle_deg;
  }
}

// Block 1 rests on block 0 across a broken joint bond under a normal load F_n; a tangential load ramps up slowly.
// It must hold until F_t = mu F_n and slide right after.
TEST(Engine, BlockSlidesOnAJointStartingExactlyAtMuFn) {
  Scene scene = elastic_scene();
  scene.numerics.damping = 0.7;
  const double mu = std::tan(30.0 * std::numbers::pi / 180);
  scene.joint.contact_friction = mu;
  const double a = 1e-3, b = 0.8e-3;
  const Topology<2> topo = build_topology(rhombus(a, b, 0, 1), 1.0, 2700.0);
  ASSERT_EQ(topo.bonds.kind[0], BondKind::joint);
  Engine<2> e(topo, scene, free_blocks(scene));
  e.break_bond(0);
  e.fix_block(0);
  e.set_block_mass(1, e.model().mass[1], 1e6 * e.model().inertia[1]);  // keep it from tipping: a pure sliding test
  const double fn = 1e4;
  BlockGroupImpl<2> load(e, {"load", {1}, GroupSettings::Mode::force, {0.0, -fn, 0.0}});
  e.attach(&load);
  e.set_dt(0.2 * e.critical_step());
  e.run(20000);  // settle under the normal load
  const double x_settled = e.state().x[1];
  const long ramp_steps = 500000;
  double slip_at = -1;
  for (long s = 1; s <= ramp_steps; ++s) {
    const double ft = 1.2 * mu * fn * double(s) / double(ramp_steps);
    load.set_value({ft, -fn, 0.0});
    e.step();
    if (std::abs(e.state().x[1] - x_settled) > 3e-7) {  // several times the elastic shear displacement (5e-8 m)
      slip_at = ft;
      break;
    }
  }
  ASSERT_GT(slip_at, 0);
  EXPECT_NEAR(slip_at / (mu * fn), 1.0, 0.01);
}

// The linear part of an intact bond and the clipped contact that replaces it carry the same force.
TEST(Engine, CompressedBondBreaksWithoutForceJumpInTheLinearPart) {
  const Scene scene = elastic_scene();
  const double a = 1e-3, b = 0.8e-3;
  const Topology<2> topo = build_topology(rhombus(a, b), 1.0, 2700.0);
  Engine<2> e(topo, scene, free_blocks(scene));
  e.edit([](ModelState<2>& s) {
    s.y[1] -= 1e-6;  // compress, with a little shear and rotation
    s.x[1] += 2e-7;
    s.theta[1] = 1e-4;
  });
  e.set_dt(1e-15);
  e.step();
  const double fn_bond = e.bond_forces(0).fn_lin;
  ASSERT_GT(fn_bond, 0);
  e.break_bond(0);
  e.step();
  ASSERT_EQ(e.state().contacts.size(), 1u);
  EXPECT_NEAR(e.state().contacts.fn[0] / fn_bond, 1.0, 0.01);
}

using verify::softening_pull;

// Pulled open, the bond reaches sigma_c, then softens linearly and breaks at 2 G_f / sigma_c, having dissipated
// G_f per unit area, on a small block and on one twice as large (the energy must not follow the block size).
TEST(SofteningBond, DissipatesItsFractureEnergyInTensionWhateverTheBlockSize) {
  const double gf = 0.5;  // J/m^2; the brittle bond of the larger block stores sigma_c^2 d / (2 E*) = 0.1 J/m^2
  for (double a : {0.5e-3, 1e-3}) {
    const verify::SofteningPullMeasure p = softening_pull(a, gf, false);
    ASSERT_TRUE(p.broke) << "a = " << a;
    EXPECT_NEAR(p.peak_stress / 7.5e6, 1.0, 0.01) << "a = " << a;
    EXPECT_NEAR(p.energy_per_area / gf, 1.0, 0.01) << "a = " << a;
    EXPECT_NEAR(p.break_opening / (2.0 * gf / 7.5e6), 1.0, 0.01) << "a = " << a;
  }
}

// Slid without opening, the bond softens from the cohesion c; at zero normal stress the failure index is linear
// in the slip, so it dissipates G_f kappa (c / sigma_c)^2 per unit area (docs/model.md).
TEST(SofteningBond, DissipatesKappaCOverSigmaSquaredTimesGfInShear) {
  const double gf = 0.5;
  const verify::SofteningPullMeasure p = softening_pull(1e-3, gf, true);
  ASSERT_TRUE(p.broke);
  EXPECT_NEAR(p.peak_stress / 7.5e6, 1.0, 0.01);
  EXPECT_NEAR(p.energy_per_area / (gf * 1.5 * 1.0 * 1.0), 1.0, 0.01);  // kappa = 1.5, c = sigma_c
}

// A fracture energy below what the bond stores at its strength cannot soften: it breaks at its strength, as a
// brittle bond, and releases sigma_c^2 d / (2 E*).
TEST(SofteningBond, TooSmallAFractureEnergyBreaksAsABrittleBond) {
  const double a = 1e-3;
  const verify::SofteningPullMeasure p = softening_pull(a, 0.01, false);
  const verify::SofteningPullMeasure brittle = softening_pull(a, 0.0, false);
  ASSERT_TRUE(p.broke && brittle.broke);
  EXPECT_EQ(p.break_opening, brittle.break_opening);
  const double d = 2.0 * 0.8 * a / 3.0, stored = 7.5e6 * 7.5e6 * d / (2.0 * 160e9);
  EXPECT_NEAR(brittle.energy_per_area / stored, 1.0, 0.02);
}

// Undamped elastic lattice between the platens (breakage off): bounded at the computed step for 1e5 steps; at 2.2
// times that step the run diverges and stops with a clear error instead of producing NaN.
TEST(Engine, StableAtComputedStepAndStopsCleanlyWhenTooLarge) {
  Scene scene = elastic_scene();
  scene.loading.platen_velocity = 0.01;
  SpecimenGeometry g;
  g.width = 0.02, g.height = 0.04, g.spacing = 0.01;
  const Topology<2> topo = build_topology(mesh_specimen(g, 0.004), 1.0, 2700.0);
  scene.numerics.threads = 1;
  auto make = [&](double factor) {
    auto sim = fixtures::with_platens(scene, topo);
    sim->set_breakage(false);
    sim->set_dt(factor * scene.numerics.dt_safety * sim->stability_limit());
    return sim;
  };
  auto stable = make(1.0);
  EXPECT_NO_THROW(stable->run(100000));
  const Energies en = stable->energies();
  EXPECT_TRUE(std::isfinite(en.kinetic));
  EXPECT_LT(en.kinetic + en.strain, 1.01 * en.work);  // no energy from nowhere
  EXPECT_GT(stable->find<Platens>()->top_force(), 0.0);
  auto unstable = make(2.2);
  try {
    unstable->run(100000);
    FAIL() << "did not diverge at 2.2 x the computed step";
  } catch (const InstabilityError& err) {
    EXPECT_NE(std::string(err.what()).find("numerics.dt"), std::string::npos) << err.what();
  }
}

// The bond stage runs a vectorised kernel (compiled for AVX-512, AVX2 or the baseline, chosen at start-up); the bond
// events and the diagnostics run the same body one bond at a time. On a deformed, partly damaged and partly broken
// specimen both give the same slot forces, shear histories and failure flags, bit for bit.
TEST(BondKernel, VectorisedKernelEqualsTheScalarBondEvaluationBitForBit) {
  Scene scene;
  scene.mesh.size = 0.003;
  const Topology<2> topo = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  Engine<2> e(topo, scene, EngineOptions::from_scene(scene));
  const Model<2>& m = e.model();
  ModelState<2> s = e.state();
  // A deformation with every regime of the linear part (closed, partly open, open) and some rotation.
  for (std::size_t b = 0; b < s.num_blocks(); ++b) {
    const double q = std::sin(12.9898 * double(b)), r = std::cos(78.233 * double(b));
    s.x[b] += 2e-7 * q - 3e-6 * (s.x[b] - 0.025);
    s.y[b] -= 1e-5 * s.y[b] + 1e-7 * r;
    s.theta[b] = 2e-4 * q * r;
    s.vx[b] = 1e-3 * r, s.vy[b] = -1e-3 * q, s.omega[b] = 0.1 * q;
  }
  for (std::size_t k = 0; k < m.num_bonds(); k += 7) s.drive[k] = 1.0 + 0.1 * double(k % 5);  // softened
  for (std::size_t k = 3; k < m.num_bonds(); k += 11) s.broken[k] = 1;
  for (std::size_t k = 0; k < m.num_bonds(); ++k) s.fs_lin[k] = 1e-3 * double(k % 13);
  Workspace<2> w;
  w.slot.assign(m.num_bonds());
  stages::update_rotations(s, w, 1);
  stages::refresh_keep(m, s, w);
  ASSERT_GT(w.damaged, 0u);
  const ModelState<2> before = s;
  StepContext c{1e-8, true, 2};
  stages::bond_forces(m, s, w, c);
  std::size_t flagged = 0, compressed = 0;
  for (const auto& list : w.flagged) flagged += list.size();
  for (std::size_t k = 0; k < m.num_bonds(); ++k) {
    const int b = int(k);
    const stages::BondEval ev = stages::eval_bond(m, before, w, b, c.dt, before.fs_lin[k], w.keep[k]);
    if (before.broken[k]) {
      EXPECT_EQ(w.slot.fx[k], 0.0) << b;
      EXPECT_EQ(s.fs_lin[k], before.fs_lin[k]) << b;
      continue;
    }
    compressed += ev.fnl > 0.0;
    EXPECT_EQ(w.slot.fx[k], ev.fx) << b;
    EXPECT_EQ(w.slot.fy[k], ev.fy) << b;
    EXPECT_EQ(w.slot.m[2 * k], ev.mi) << b;
    EXPECT_EQ(w.slot.m[2 * k + 1], ev.mj) << b;
    EXPECT_EQ(s.fs_lin[k], ev.fsl) << b;
  }
  EXPECT_GT(compressed, 0u);
  EXPECT_LT(compressed, m.num_bonds());
  RecordProperty("flagged", std::to_string(flagged));
}

// The bond stage flags the bonds whose failure test held for the bond events, which then apply the law. That
// pre-filter is the law's own test (BondLoad::exceeds), called in the kernel's vector lanes: on a specimen deformed
// so that some bonds are past their strength, some softened (a larger scale) and some broken, the kernel flags
// exactly the bonds the law fails at their scale, and no other.
TEST(BondKernel, FailurePreFilterIsTheLawsTestBitForBit) {
  Scene scene;
  scene.mesh.size = 0.003;
  const Topology<2> topo = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  Engine<2> e(topo, scene, EngineOptions::from_scene(scene));
  const Model<2>& m = e.model();
  ModelState<2> s = e.state();
  for (std::size_t b = 0; b < s.num_blocks(); ++b) {  // strains of 1e-4 in tension and shear: about the strength
    const double q = std::sin(12.9898 * double(b)), r = std::cos(78.233 * double(b));
    s.x[b] += 1e-4 * (s.x[b] - 0.025) + 3e-7 * q;
    s.y[b] += 0.5e-4 * s.y[b] + 3e-7 * r;
    s.theta[b] = 3e-4 * q * r;
  }
  for (std::size_t k = 0; k < m.num_bonds(); k += 7) s.drive[k] = 1.0 + 0.2 * double(k % 5);  // softened
  for (std::size_t k = 3; k < m.num_bonds(); k += 11) s.broken[k] = 1;
  Workspace<2> w;
  w.slot.assign(m.num_bonds());
  stages::update_rotations(s, w, 1);
  stages::refresh_keep(m, s, w);
  const ModelState<2> before = s;
  stages::bond_forces(m, s, w, StepContext{1e-8, true, 2});
  std::size_t flagged = 0, by_law = 0;
  for (std::size_t k = 0; k < m.num_bonds(); ++k) {
    bool fails = false;
    if (!before.broken[k]) {
      const stages::BondEval ev = stages::eval_bond(m, before, w, int(k), 1e-8, before.fs_lin[k], w.keep[k]);
      const BondFrames& f = m.frame;
      const ParallelBond& law = m.law[m.material[k]].bond;
      const BondLoad q = BondLoad::of(f.tension_limit[k], f.cohesion_A[k], f.tan_phi[k], f.beta_m[k], ev.fnb, ev.fsb,
                                      ev.mb, f.inv_L[k], law.moment_arm());
      fails = q.failure(before.drive[k] > 0.0 ? before.drive[k] : 1.0) != BreakMode::none;
    }
    by_law += fails;
    flagged += w.flag[k] != 0;
    ASSERT_EQ(w.flag[k] != 0, fails) << "bond " << k;
  }
  EXPECT_GT(by_law, 0u) << "no bond is past its strength: the test needs some";
  EXPECT_LT(by_law, m.num_bonds());
  std::size_t listed = 0;
  for (const auto& list : w.flagged) listed += list.size();
  EXPECT_EQ(listed, flagged);  // every flagged bond is handed to the events, in the per-thread lists
}

// The threads share the blocks and bonds in ranges (Workspace::Partition); everything a step computes, the damping
// work summed per block grain included, is the same to the bit at 1, 2 and 3 threads, here through breakage, and
// when the stages get smaller teams than asked (inside another parallel region).
// 1 500 steps of the paper's specimen at 3 mm, loaded fast enough to break bonds within them, at half the stability
// limit: the state and the energies at the end, and the engine's broad-phase counts.
struct BreakingRun {
  ModelState<2> state;
  Energies energy;
  std::size_t updates = 0, rebuilds = 0;
};
BreakingRun run_breaking(const Topology<2>& topo, const Scene& scene) {
  const auto sim = fixtures::with_platens(scene, topo);
  sim->set_dt(0.5 * sim->stability_limit());
  sim->run(1500);
  const Engine<2>& e = sim->engine();
  return {e.state(), e.energies(), e.broad_phase().updates, e.broad_phase().rebuilds};
}

TEST(Engine, StepsAndEnergiesAreBitIdenticalAtOneTwoAndThreeThreads) {
  Scene scene;
  scene.mesh.size = 0.003;
  scene.loading.platen_velocity = 0.5;  // breaks within the 1 500 steps
  const Topology<2> topo = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  std::vector<ModelState<2>> end;
  std::vector<Energies> energy;
  for (const int threads : {1, 2, 3}) {
    scene.numerics.threads = threads;
    const BreakingRun r = run_breaking(topo, scene);
    end.push_back(r.state), energy.push_back(r.energy);
  }
  {  // 2 threads asked for inside another parallel region: the stages get teams of one, which must still do it all
    scene.numerics.threads = 2;
    const auto sim = fixtures::with_platens(scene, topo);
    sim->set_dt(0.5 * sim->stability_limit());
    const int levels = omp_get_max_active_levels();
    omp_set_max_active_levels(1);
#pragma omp parallel num_threads(2)
    {
#pragma omp single
      sim->run(1500);
    }
    omp_set_max_active_levels(levels);
    end.push_back(sim->engine().state());
    energy.push_back(sim->energies());
  }
  ASSERT_GT(end[0].cracks.size(), 0u);
  ASSERT_GT(energy[0].damping, 0.0);
  for (std::size_t k = 1; k < end.size(); ++k) {
    SCOPED_TRACE(testing::Message() << (k < 3 ? k + 1 : 2) << " threads" << (k < 3 ? "" : ", nested"));
    EXPECT_EQ(end[k].x, end[0].x);
    EXPECT_EQ(end[k].theta, end[0].theta);
    EXPECT_EQ(end[k].vx, end[0].vx);
    EXPECT_EQ(end[k].cracks.size(), end[0].cracks.size());
    EXPECT_EQ(end[k].contacts.key, end[0].contacts.key);
    EXPECT_EQ(end[k].contacts.fs, end[0].contacts.fs);
    EXPECT_EQ(energy[k].damping, energy[0].damping);
    EXPECT_EQ(energy[k].strain, energy[0].strain);
    EXPECT_EQ(energy[k].kinetic, energy[0].kinetic);
    EXPECT_EQ(energy[k].friction, energy[0].friction);
  }
}

// After bond breaks the broad phase adds the broken pairs and the blocks that gained a free face to its lists
// instead of rebuilding them (numerics.update_after_breaks). The lists then differ from a rebuild's, but only in
// pairs that do not touch: every step must give the rebuilding run's numbers to the bit, and every pair that
// touches must be listed in both with the same history.
TEST(BroadPhase, UpdatingTheListsAfterBreaksGivesTheRebuildsNumbersToTheBit) {
  Scene scene;
  scene.mesh.size = 0.003, scene.numerics.threads = 1;
  scene.loading.platen_velocity = 0.5;  // breaks within the 1 500 steps
  const Topology<2> topo = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  std::vector<ModelState<2>> end;
  std::vector<Energies> energy;
  std::vector<std::size_t> updates, rebuilds;
  for (const bool update : {true, false}) {
    scene.numerics.update_after_breaks = update;
    const BreakingRun r = run_breaking(topo, scene);
    end.push_back(r.state), energy.push_back(r.energy), updates.push_back(r.updates), rebuilds.push_back(r.rebuilds);
  }
  ASSERT_GT(end[1].cracks.size(), 20u);
  EXPECT_GT(updates[0], 10u) << "the lists were never updated";
  EXPECT_EQ(updates[1], 0u);
  EXPECT_LT(rebuilds[0], rebuilds[1]);
  EXPECT_EQ(end[0].x, end[1].x);
  EXPECT_EQ(end[0].y, end[1].y);
  EXPECT_EQ(end[0].theta, end[1].theta);
  EXPECT_EQ(end[0].vx, end[1].vx);
  EXPECT_EQ(end[0].omega, end[1].omega);
  EXPECT_EQ(end[0].broken, end[1].broken);
  EXPECT_EQ(end[0].cracks.size(), end[1].cracks.size());
  EXPECT_EQ(energy[0].strain, energy[1].strain);
  EXPECT_EQ(energy[0].friction, energy[1].friction);
  EXPECT_EQ(energy[0].damping, energy[1].damping);
  const ContactPairs &a = end[0].contacts, &b = end[1].contacts;
  std::size_t touching = 0;
  for (std::size_t p = 0; p < b.size(); ++p) {
    if (!(b.fn[p] > 0.0)) continue;
    ++touching;
    const auto at = std::lower_bound(a.key.begin(), a.key.end(), b.key[p]);
    ASSERT_TRUE(at != a.key.end() && *at == b.key[p]) << "a touching pair is missing from the updated lists";
    const std::size_t q = std::size_t(at - a.key.begin());
    EXPECT_EQ(a.fn[q], b.fn[p]);
    EXPECT_EQ(a.fs[q], b.fs[p]);
  }
  EXPECT_GT(touching, 0u);
}

// The split of bonds and blocks among the threads follows their measured speed, so it differs from run to run:
// no number may depend on it. Two threads with the boundaries moved every 100 steps to uneven places (blocks in
// whole grains) give the one-thread run to the bit, through bond breaks and contact rebuilds.
TEST(Engine, StepsDoNotDependOnWhereTheThreadsSplitTheWork) {
  Scene scene;
  scene.mesh.size = 0.003;
  scene.loading.platen_velocity = 0.5;
  const Topology<2> topo = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  std::vector<ModelState<2>> end;
  std::vector<Energies> energy;
  std::vector<double> top_force;
  for (const int threads : {1, 2}) {
    scene.numerics.threads = threads;
    // The team keeps its two threads (under `ctest -j` another process may hold a core, and the team would shrink
    // and set its own partition up).
    const auto sim = fixtures::with_platens(scene, topo, [](EngineOptions& o) { o.adapt_threads = false; });
    Engine<2>& e = sim->engine();
    e.set_dt(0.5 * sim->stability_limit());
    const int nb = int(topo.blocks.size()), nbond = int(topo.bonds.size());
    const int grain = Workspace<2>::Partition::kBlockGrain;
    for (int round = 0; round < 15; ++round) {
      e.run(threads == 2 && round == 0 ? 1 : 0);  // the first step sets the partition up
      if (threads == 2) {
        Workspace<2>::Partition& p = e.partition();
        ASSERT_EQ(p.threads, 2);
        const double f = 0.1 + 0.8 * ((round * 7) % 11) / 10.0;  // 0.1 .. 0.9 of the items on the first thread
        p.bond[1] = int(f * nbond);
        p.block[1] = std::min(nb, int(std::lround((1.0 - f) * nb / grain)) * grain);
      }
      e.run(threads == 2 && round == 0 ? 99 : 100);
    }
    end.push_back(e.state());
    energy.push_back(e.energies());
    top_force.push_back(sim->find<Platens>()->top_force());
  }
  ASSERT_GT(end[0].cracks.size(), 0u);
  EXPECT_EQ(end[1].x, end[0].x);
  EXPECT_EQ(end[1].theta, end[0].theta);
  EXPECT_EQ(end[1].vy, end[0].vy);
  EXPECT_EQ(end[1].cracks.size(), end[0].cracks.size());
  EXPECT_EQ(end[1].contacts.fs, end[0].contacts.fs);
  EXPECT_EQ(top_force[1], top_force[0]);
  EXPECT_EQ(energy[1].damping, energy[0].damping);
  EXPECT_EQ(energy[1].friction, energy[0].friction);
  EXPECT_EQ(energy[1].strain, energy[0].strain);
}

// The stages run each thread's range in pieces, and a thread done with its own takes what is left of the others'
// (Workspace<2>::run_pieces): every item runs exactly once, whatever the team, and a thread held up finds its range
// taken over by the others.
TEST(Engine, PiecesRunOnceAndAThreadHeldUpLeavesItsRangeToTheOthers) {
  const std::vector<int> bounds = {0, 1000, 1300, 5000};
  for (const int team : {1, 2, 3}) {
    std::vector<Workspace<2>::Cursor> next(3);
    std::vector<int> runs(5000, 0), items(std::size_t(team), 0);
    auto taken = std::vector<std::vector<std::array<int, 2>>>(std::size_t(team));
#pragma omp parallel num_threads(team)
    {
      const int t = omp_get_thread_num();
      if (t == 0 && team > 1) std::this_thread::sleep_for(std::chrono::milliseconds(50));  // held up
      items[std::size_t(t)] = Workspace<2>::run_pieces(bounds, next, 256, t, [&](int lo, int hi) {
        taken[std::size_t(t)].push_back({lo, hi});
        for (int k = lo; k < hi; ++k) {
#pragma omp atomic
          ++runs[std::size_t(k)];
        }
      });
    }
    EXPECT_EQ(std::count(runs.begin(), runs.end(), 1), 5000) << team << " threads";
    int total = 0;
    for (int n : items) total += n;
    EXPECT_EQ(total, 5000);
    for (const auto& list : taken)
      for (const auto& piece : list) {  // no piece crosses a range's end
        const auto end = std::upper_bound(bounds.begin(), bounds.end(), piece[0]);
        EXPECT_LE(piece[1], *end);
      }
    if (team > 1) EXPECT_LT(items[0], 1000) << "the others took the pieces of the thread held up";
    if (team == 1) EXPECT_EQ(items[0], 5000);
  }
}

// The jacket pushes on every outer edge with p t L along its inward normal; a block that lost every bond and every
// contact (a fragment that broke off) gets no pressure and is counted (the rule in dem/boundary/jacket.cpp). The
// work it books is the power of its forces: with the blocks of the right side moving outward at v, -p t L v per
// second over the length L of their edges.
TEST(Jacket, PressurePushesConnectedEdgesAndLeavesALooseFragmentAlone) {
  Scene scene;
  scene.mesh.size = 0.004;
  scene.numerics.damping = 0.0;
  scene.numerics.threads = 1;
  SimulationImpl<2> sim(scene, make_mesh(scene));
  const Topology<2>& topo = sim.topology();
  Engine<2>& e = sim.engine();
  const double p = 5e6, t = scene.specimen.thickness;
  Jacket& jacket = sim.add_jacket(p);
  sim.set_breakage(false);
  // The jacket's edges: the boundary edges that are not on the platens' sides.
  const auto& E = topo.boundary;
  std::vector<std::size_t> sides;
  for (std::size_t k = 0; k < E.size(); ++k)
    if (E.side[k] != Side::top && E.side[k] != Side::bottom) sides.push_back(k);
  // One block on the left side: every bond broken and moved 10 mm out, so it touches nothing.
  int loose = -1;
  for (std::size_t k : sides)
    if (E.side[k] == Side::left && loose < 0) loose = E.block[k];
  ASSERT_GE(loose, 0);
  for (int o2 = topo.bond_offset[std::size_t(loose)]; o2 < topo.bond_offset[std::size_t(loose) + 1]; ++o2)
    e.break_bond(topo.bond_of[std::size_t(o2)]);
  e.edit([&](ModelState<2>& s) { s.x[std::size_t(loose)] -= 0.01; });
  int loose_edges = 0;
  for (std::size_t k : sides) loose_edges += E.block[k] == loose;
  // The blocks whose jacket edges all lie on the right side move outward at v: their edges' pressure does work.
  const double v = 1e-3, dt = 1e-9;
  std::vector<char> right(topo.blocks.size(), 0);
  for (std::size_t k : sides)
    if (E.side[k] == Side::right) right[std::size_t(E.block[k])] = 1;
  for (std::size_t k : sides)
    if (E.side[k] != Side::right) right[std::size_t(E.block[k])] = 0;
  double right_length = 0;
  for (std::size_t k : sides)
    if (right[std::size_t(E.block[k])]) right_length += E.length[k];
  ASSERT_GT(right_length, 0.5 * topo.height());
  e.edit([&](ModelState<2>& s) {
    for (std::size_t b = 0; b < s.num_blocks(); ++b) s.vx[b] = right[b] ? v : 0.0;
  });
  e.set_dt(dt);
  e.step();
  EXPECT_EQ(jacket.faces_lost(), loose_edges);
  EXPECT_EQ(e.state().fx[std::size_t(loose)], 0.0);  // no bond, no contact, no pressure
  EXPECT_EQ(e.state().fy[std::size_t(loose)], 0.0);
  EXPECT_NEAR(jacket.work(), -p * t * right_length * v * dt, 1e-9 * p * t * right_length * v * dt);
  // The jacket's net force on a connected block with one edge on the right side: p t L inward (-x).
  for (std::size_t k : sides) {
    const int b = E.block[k];
    int edges = 0;
    for (std::size_t q : sides) edges += E.block[q] == b;
    if (edges != 1 || E.side[k] != Side::right) continue;
    std::vector<double> fx, fy, m;
    jacket.set_pressure(0.0);
    e.evaluate_forces(fx, fy, m);
    const double without = fx[std::size_t(b)];
    jacket.set_pressure(p);
    e.evaluate_forces(fx, fy, m);
    EXPECT_NEAR(fx[std::size_t(b)] - without, -p * E.length[k] * t, 1e-6 * p * E.length[k] * t);
    break;
  }
}

TEST(Ucs, SmallSpecimenSmokeRunBreaksAndWritesACurve) {
  Scene scene;
  scene.mesh.size = 0.004;
  scene.joint_set.dip_deg = 60;
  scene.numerics.threads = 1;
  const TestResult r = run_test("ucs", scene, make_mesh(scene));
  EXPECT_GT(r.peak_stress, 1e6);
  EXPECT_GT(r.youngs_modulus, 1e9);
  EXPECT_EQ(r.stop_reason, "post_peak");
  EXPECT_GT(r.crack_counts.total(), 0);
  EXPECT_GT(r.curve.size(), 10u);
  EXPECT_LT(r.platen_force_mismatch, 0.05);
}

TEST(Ucs, TimeStepAboveCriticalIsRefusedWithTheNumbers) {
  Scene scene;
  scene.mesh.size = 0.005;
  scene.numerics.dt = 1e-3;
  try {
    run_test("ucs", scene, make_mesh(scene));
    FAIL();
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("numerics.dt = 0.001 s is above the critical time step"), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace rbdem
