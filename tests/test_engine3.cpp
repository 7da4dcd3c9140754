// The 3D engine (dem/engine3.hpp) and SimulationImpl<3>: the platens' overlap against closed forms, the explicit
// elastic state against the static solution, a uniaxial test of a jointed cylinder to failure, bit-identical
// results at 1 and 2 threads and after a snapshot's restore.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <atomic>
#include <map>
#include <stdexcept>
#include <thread>

#include "dem/boundary/components3.hpp"
#include "dem/driver/driver.hpp"
#include "dem/simulation_impl3.hpp"
#include "dem/specimen_mesh3.hpp"
#include "dem/static_start3.hpp"

namespace rbdem {
namespace {

// The part of the unit right tetrahedron (0, e_x, e_y, e_z) beyond planes of every kind of cut: its volume
// against the closed forms, and the two sides of one plane summing to the whole.
TEST(Platens3, TetBeyondPlaneMatchesClosedForms) {
  const std::array<Vec3, 4> v{Vec3{0, 0, 0}, Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}};
  // Below z = c (depth c - z): the whole less the corner tetrahedron above it, (1 - c)^3 / 6.
  for (double c : {0.1, 0.5, 0.9}) {
    const TetOverlap o = tet_beyond_plane(v, {c, c, c, c - 1});
    EXPECT_NEAR(o.volume, (1 - std::pow(1 - c, 3)) / 6, 1e-15);
    EXPECT_NEAR(o.area, 0.5 * (1 - c) * (1 - c), 1e-14);  // the section: the triangle at z = c
    // Above z = c: the corner.
    const TetOverlap a = tet_beyond_plane(v, {-c, -c, -c, 1 - c});
    EXPECT_NEAR(a.volume, std::pow(1 - c, 3) / 6, 1e-15);
    EXPECT_NEAR(a.centroid.z, c + 0.25 * (1 - c), 1e-14);
    EXPECT_NEAR(o.volume + a.volume, 1.0 / 6, 1e-15);
    // The whole's centroid from the two parts.
    EXPECT_NEAR(o.volume * o.centroid.x + a.volume * a.centroid.x, 0.25 / 6, 1e-15);
  }
  // A plane x + y = c cuts two vertices from two: the sides sum to the whole and the first moment to the whole's.
  for (double c : {0.3, 0.7}) {
    const TetOverlap p = tet_beyond_plane(v, {c, c - 1, c - 1, c});
    const TetOverlap q = tet_beyond_plane(v, {-c, 1 - c, 1 - c, -c});
    EXPECT_NEAR(p.volume + q.volume, 1.0 / 6, 1e-15);
    EXPECT_NEAR(p.volume * p.centroid.z + q.volume * q.centroid.z, 0.25 / 6, 1e-15);
    EXPECT_NEAR(p.volume, c * c / 2 - c * c * c / 3, 1e-15);  // int_0^c s (1 - s) ds
    EXPECT_NEAR(p.area, c * std::sqrt(2.0) * (1 - c), 1e-14);  // the rectangle x + y = c: c sqrt(2) by 1 - c
  }
  // A face pressed by d: the overlap is the face's area times d to first order.
  const double d = 1e-6;
  const TetOverlap f = tet_beyond_plane(v, {d, d, d, d - 1});
  EXPECT_NEAR(f.volume / (0.5 * d), 1.0, 2e-6);
  EXPECT_NEAR(f.area, 0.5, 1e-6);
}

// A jointed cylinder, 10 mm tets (about two thousand blocks), memoised per dip.
const TetMesh& cylinder(double dip) {
  static std::map<double, TetMesh> cache;
  auto it = cache.find(dip);
  if (it == cache.end()) {
    SpecimenGeometry3 g;
    g.set1.dip_deg = dip;
    it = cache.emplace(dip, mesh_specimen3(g, 0.01)).first;
  }
  return it->second;
}

Scene scene3(double dip) {
  Scene s;
  s.joint_set.dip_deg = dip;
  s.numerics.threads = 1;
  return s;
}

// Put into the static solution at a load below the first break and held there, the explicit model stays at rest:
// its bonds and platens give the static forces (the two models are one linear model).
TEST(Engine3, ExplicitStateAtTheStaticSolutionStaysAtRest) {
  const Scene scene = scene3(60);
  SimulationImpl<3> sim(scene, cylinder(60));
  Platens& platens = sim.add_platens({0.0, 0.0});
  StaticOptions so;
  so.platen_displacement = 1e-6 * sim.specimen().height();
  const StaticResult st = sim.solve_static(so);
  ASSERT_GT(st.first_break_factor, 1.0);
  ASSERT_GT(st.top_force, 0.0);
  EXPECT_NEAR(st.top_force / st.bottom_force, 1.0, 1e-9);
  const double lambda = 0.5 * st.first_break_factor;
  sim.apply_static({}, st, lambda, 0.0);
  sim.set_dt(0.5 * sim.stability_limit(300));
  sim.set_breakage(false);
  sim.step();
  // The first step's platen force is the contact law at the static overlap: the spring of the static solve up to
  // the overlap volume's second-order terms.
  EXPECT_NEAR(platens.top_force() / (lambda * st.top_force), 1.0, 1e-3);
  // Every block's resultant is small against its largest bond force.
  const BlockStates b = sim.block_states();
  double worst = 0, scale = lambda * st.top_force;
  for (double f : b.force) worst = std::max(worst, std::abs(f));
  EXPECT_LT(worst, 1e-3 * scale) << "the explicit forces at the static state are out of balance";
  // Held for 200 steps it stays there: the platen force within 0.5 % of the static one, the kinetic energy a
  // hundred-thousandth of the strain energy. What differs: a linear part near the open/closed boundary, which the
  // static solve takes closed or open by the sign at the face's centroid and the explicit law closes over the
  // compressed part of the face only, and the platen contact's rotational stiffness on the overlap volume.
  sim.run(200);
  EXPECT_NEAR(platens.top_force() / (lambda * st.top_force), 1.0, 5e-3);
  EXPECT_LT(sim.energies().kinetic, 1e-5 * sim.energies().strain);
}

// Two tetrahedra bonded on their shared face, pressed together with a little shear and relative rotation: when the
// bond breaks, the linear part goes on in the same face as the broken bond's contact, so its normal force and its
// shear carry on without a jump (within 1 %); the force between the blocks drops by the parallel bond's share only
// (docs/theory.md 11.6, the linear parallel bond: the bond's part is what breaks).
TEST(Engine3, CompressedBondBreaksWithoutForceJumpInTheLinearPart) {
  const double a = 2e-3;
  TetMesh m;
  m.nodes = {{0, 0, 0}, {a, 0, 0}, {0, a, 0}, {0, 0, a}, {a, a, a}};
  m.tets = {{0, 1, 2, 3}, {4, 2, 1, 3}};
  m.layer = {0, 0};
  m.layer_names = {"rock"};
  m.boundary = {{{4, 2, 3}, 1, FaceTag::top}};
  Scene scene;
  scene.numerics.threads = 1;
  scene.rock.contact_friction = 0.5;
  SimulationImpl<3> sim(scene, m);
  Engine<3>& e = sim.engine();
  ASSERT_EQ(e.model().num_bonds(), 1u);
  // Block 1 pushed towards block 0 along the face normal (1, 1, 1)/sqrt(3) and turned a little; then slid along
  // the face by 2e-7 m in one tiny step (the linear part's shear is incremental: it needs the slip's velocity), and
  // stopped.
  const double dt = 1e-15, slide = 2e-7 / std::sqrt(2.0);
  e.edit([&](ModelState<3>& s) {
    const double push = 1e-6 / std::sqrt(3.0);
    s.x[1] -= push, s.y[1] -= push, s.z[1] -= push;
    const Quat q = normalized(Quat{1.0, 2e-5, -1e-5, 3e-5});
    s.qw[1] = q.w, s.qx[1] = q.x, s.qy[1] = q.y, s.qz[1] = q.z;
    s.vx[1] = slide / dt, s.vy[1] = -slide / dt;
  });
  e.set_dt(dt);
  e.step();
  e.edit([](ModelState<3>& s) { s.vx[1] = s.vy[1] = s.vz[1] = s.wx[1] = s.wy[1] = s.wz[1] = 0.0; });
  e.step();
  const stages::FaceBondOut before = e.bond_forces(0);
  ASSERT_GT(before.fn_lin, 0.0) << "the face is not compressed";
  const double shear_before = std::hypot(before.fs1_lin, before.fs2_lin);
  ASSERT_GT(shear_before, 0.0);
  ASSERT_LT(shear_before, scene.rock.contact_friction * before.fn_lin) << "the shear would slip: pick a smaller one";
  const double total_before = norm(before.f), linear_before = std::hypot(before.fn_lin, shear_before);
  e.break_bond(0);
  e.step();
  const stages::FaceBondOut after = e.bond_forces(0);
  EXPECT_NEAR(after.fn_lin / before.fn_lin, 1.0, 0.01);
  EXPECT_NEAR(after.fs1_lin / before.fs1_lin, 1.0, 0.01);
  EXPECT_NEAR(after.fs2_lin / before.fs2_lin, 1.0, 0.01);
  // What the blocks feel after the break is the linear part alone; before it, the parallel bond's part as well.
  EXPECT_NEAR(norm(after.f) / linear_before, 1.0, 0.01);
  EXPECT_GT(total_before, 1.5 * norm(after.f));
  std::printf("linear part after / before: normal %.6f, shear %.6f; force between the blocks %.4g N -> %.4g N\n",
              after.fn_lin / before.fn_lin, std::hypot(after.fs1_lin, after.fs2_lin) / shear_before, total_before,
              norm(after.f));
}

// The block-wise estimate stays below the limit; a loaded cylinder (the static state at half the first break) shaken
// by a random velocity field calms down under the default local damping at 0.7 and 0.9 x the limit and blows up at
// 1.5 x: the limit bounds the explicit law's stiffness (static_start3.hpp) without being far below the true one.
// Without damping a lattice whose linear parts sit at the open/closed boundary gains energy even below the limit
// (docs/model.md, "The 3D model": the incremental shear of a linear part whose closed area changes within a
// vibration is not conservative), so the check is of the damped scheme that runs use.
TEST(Engine3, StabilityLimitIsTheExplicitSchemesLimit) {
  const Scene scene = scene3(60);
  auto run_at = [&](double factor) {
    SimulationImpl<3> sim(scene, cylinder(60));
    sim.add_platens({0.0, 0.0});
    const double limit = sim.stability_limit(300);
    EXPECT_LT(sim.block_step_estimate(), limit);
    EXPECT_GT(sim.block_step_estimate(), 0.2 * limit);
    StaticOptions so;
    so.platen_displacement = 1e-6 * sim.specimen().height();
    const StaticResult st = sim.solve_static(so);
    sim.apply_static({}, st, 0.5 * st.first_break_factor, 0.0);
    sim.set_dt(factor * limit);
    sim.set_breakage(false);
    sim.engine().edit([](ModelState<3>& s) {
      for (std::size_t b = 0; b < s.num_blocks(); ++b) s.vz[b] += 1e-3 * std::sin(1.7 * double(b));
    });
    const double e0 = sim.energies().kinetic;
    try {
      sim.run(2000);
    } catch (const InstabilityError&) {
      return 1e300;
    }
    return sim.energies().kinetic / e0;
  };
  EXPECT_LT(run_at(0.7), 0.1);  // numerics.dt_safety's default
  EXPECT_LT(run_at(0.9), 0.1);
  EXPECT_GT(run_at(1.5), 1e3);
}

TestResult ucs(int threads, double dip = 60) {
  Scene scene = scene3(dip);
  scene.numerics.threads = threads;
  RunOptions ro;
  ro.curve_points = 200;
  return run_test("ucs", scene, cylinder(dip), ro);
}

// A jointed cylinder in uniaxial compression: the elastic start, the peak, cracks on the joints and the rock, the
// post-peak stop; the same numbers at one and two threads.
TEST(Engine3, UniaxialCylinderFailsAndIsDeterministic) {
  const TestResult one = ucs(1);
  ASSERT_TRUE(one.completed) << one.watchdog_message;
  EXPECT_EQ(one.dimension, 3);
  EXPECT_GT(one.peak_stress, 1e6);
  EXPECT_LT(one.peak_stress, 500e6);
  EXPECT_GT(one.cracks.size(), 0u);
  EXPECT_GT(one.elastic_start_strain, 0.0);
  const TestResult two = ucs(2);
  EXPECT_EQ(one.peak_stress, two.peak_stress);
  EXPECT_EQ(one.steps, two.steps);
  EXPECT_EQ(one.cracks.size(), two.cracks.size());
}

// The jacket's load at rest: -p A n on every lateral face, whose resultant force and moment vanish (the lateral
// surface of a cylinder is closed around its axis), and whose radial part is p times the lateral area.
TEST(Jacket3, ReferenceLoadIsBalanced) {
  const Scene scene = scene3(60);
  SimulationImpl<3> sim(scene, cylinder(60));
  sim.add_platens({0.0, 0.0});
  const double p = 1e6;
  const std::vector<double> load = sim.pressure_load(p);
  const Model<3>& m = sim.engine().model();
  Vec3 F, M;
  double radial = 0, lateral_area = 0;
  for (std::size_t b = 0; b < m.num_blocks(); ++b) {
    const Vec3 f{load[6 * b], load[6 * b + 1], load[6 * b + 2]};
    F += f, M += Vec3{load[6 * b + 3], load[6 * b + 4], load[6 * b + 5]} + cross(m.x0[b], f);
  }
  for (const SurfaceFace& f : m.surface) {
    if (f.tag != FaceTag::lateral) continue;
    const Vec3 c = m.x0[std::size_t(f.block)] + f.r, er = Vec3{c.x - m.axis[0], c.y - m.axis[1], 0.0};
    radial += p * f.area * dot(f.normal, (1.0 / norm(er)) * er), lateral_area += f.area;
  }
  EXPECT_LT(norm(F), 1e-9 * p * lateral_area);
  EXPECT_LT(norm(M), 1e-9 * p * lateral_area * 0.1);
  EXPECT_NEAR(radial / (p * lateral_area), 1.0, 0.01);  // the faces' normals are radial to the facets' tilt
}

// The confined test of the cylinder (the jacket's pressure, the isotropic static state, the axial start from it):
// it completes and its peak rises by more than the pressure.
TEST(Engine3, ConfinedCylinderIsStrongerThanUnconfined) {
  Scene scene = scene3(60);
  scene.loading.confining_pressure = 10e6;
  RunOptions ro;
  ro.curve_points = 200;
  const TestResult confined = run_test("triaxial", scene, cylinder(60), ro);
  ASSERT_TRUE(confined.completed) << confined.watchdog_message;
  EXPECT_EQ(confined.confining_pressure, 10e6);
  const TestResult unconfined = ucs(1);
  EXPECT_GT(confined.peak_stress, unconfined.peak_stress + 10e6);
}

// A snapshot taken mid-run and restored into a fresh simulation continues bit for bit.
TEST(Engine3, SnapshotRestoreContinuesBitForBit) {
  const Scene scene = scene3(30);
  auto make = [&] {
    auto sim = std::make_unique<SimulationImpl<3>>(scene, cylinder(30));
    sim->add_platens({0.05, 0.3});
    sim->set_dt(0.8 * sim->block_step_estimate());
    return sim;
  };
  auto a = make();
  a->run(300);
  const Snapshot snap = a->snapshot();
  a->run(200);
  auto b = make();
  b->restore(snap);
  b->run(200);
  EXPECT_EQ(a->pose(), b->pose());
  EXPECT_EQ(a->find<Platens>()->top_force(), b->find<Platens>()->top_force());
}

// A cylinder cracked by a fast platen (a few hundred former non-neighbours overlap): a few hundred steps.
constexpr double kFastPlaten = 0.5;  // m/s
constexpr long kCrackSteps = 300;

struct CrackedRun {
  std::vector<double> pose;
  ContactStates contacts;
  Energies energies;
  double contact_energy;  // the contacts' own sum (BlockContacts3::stored_energy)
  std::size_t cracks;
};

BlockContacts3& block_contacts(SimulationImpl<3>& sim) {
  for (BoundaryHooks<3>* h : sim.engine().hooks())
    if (auto* c = dynamic_cast<BlockContacts3*>(h)) return *c;
  throw std::logic_error("no BlockContacts3 installed");
}

// The hook's step as the engine runs it on two threads (begin_step, both threads' prepare_forces side by side, then
// add_forces), with dt = 0 so that each pair's force is the one contact_states() reports: the block sums must be
// those of the pairs in pair order (force on j +, on i -, the moments about the centroids), to the bit.
void expect_pair_order_sums(SimulationImpl<3>& sim) {
  const Model<3>& m = sim.engine().model();
  const ModelState<3>& s = sim.engine().state();
  BlockContacts3& contacts = block_contacts(sim);
  contacts.begin_step(m, s);  // the pair list renewed first if due (the last step broke bonds, say)
  const ContactStates c = sim.contact_states();
  std::vector<Vec3> f_want(m.num_blocks()), m_want(m.num_blocks());
  for (std::size_t k = 0; k < c.size(); ++k) {
    const std::size_t i = std::size_t(c.i[k]), j = std::size_t(c.j[k]);
    const Vec3 f{c.force[3 * k], c.force[3 * k + 1], c.force[3 * k + 2]};
    const Vec3 p{c.point[3 * k], c.point[3 * k + 1], c.point[3 * k + 2]};
    f_want[j] += f, f_want[i] -= f;
    m_want[j] += cross(p - s.position(j), f);
    m_want[i] -= cross(p - s.position(i), f);
  }
  std::atomic<int> ready{0};
  auto share = [&](int t) {
    for (ready.fetch_add(1); ready.load() < 2;) {}  // both threads start together and take pieces side by side
    contacts.prepare_forces(m, s, 0.0, t, 2);
  };
  std::thread other(share, 1);
  share(0);
  other.join();
  std::vector<Vec3> f_got(m.num_blocks()), m_got(m.num_blocks());
  contacts.add_forces(m, s, f_got, m_got, 0.0, true);
  auto same = [](Vec3 a, Vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; };
  std::size_t differ = 0;
  for (std::size_t b = 0; b < m.num_blocks(); ++b) differ += !same(f_got[b], f_want[b]) || !same(m_got[b], m_want[b]);
  EXPECT_GT(c.size(), 0u);
  EXPECT_EQ(differ, 0u) << "blocks whose contact force or moment is not the pair-order sum";
}

// The contacts between blocks that were never neighbours on a cracked cylinder: their rebuild runs serially at each
// step's start, their narrow phase on the step's threads (each pair into its own record) and their sums in pair
// order, so the blocks' poses, the contact forces and the energies are the same bits on one and on two threads, and
// a two-thread step's block sums are those of the pairs in pair order. Summed per thread and then across the threads,
// the sums of blocks with three or more touching pairs and the energy's would move in their last bits.
TEST(Contacts3, ParallelNarrowPhaseIsBitIdenticalAtOneAndTwoThreads) {
  auto run = [](int threads) {
    Scene scene = scene3(60);
    scene.numerics.threads = threads;
    SimulationImpl<3> sim(scene, cylinder(60), {}, [](EngineOptions& e) { e.adapt_threads = false; });
    sim.add_platens({kFastPlaten, 0.3});
    sim.set_dt(0.8 * sim.block_step_estimate());
    sim.run(kCrackSteps);
    CrackedRun r{sim.pose(), sim.contact_states(), sim.energies(), block_contacts(sim).stored_energy(),
                 sim.cracks().size()};
    for (int k = 0; threads == 2 && k < 5; ++k) expect_pair_order_sums(sim), sim.step();  // five splits
    return r;
  };
  const CrackedRun one = run(1), two = run(2);
  ASSERT_GT(one.cracks, 0u);
  ASSERT_GT(one.contacts.size(), 0u) << "no pair of former non-neighbours touches: the check would be empty";
  EXPECT_EQ(one.cracks, two.cracks);
  EXPECT_EQ(one.pose, two.pose);
  EXPECT_EQ(one.contacts.i, two.contacts.i);
  EXPECT_EQ(one.contacts.j, two.contacts.j);
  EXPECT_EQ(one.contacts.force, two.contacts.force);
  EXPECT_EQ(one.contacts.normal_force, two.contacts.normal_force);
  EXPECT_EQ(one.contacts.shear_force, two.contacts.shear_force);
  EXPECT_EQ(one.contact_energy, two.contact_energy);
  EXPECT_EQ(one.energies.kinetic, two.energies.kinetic);
  EXPECT_EQ(one.energies.strain, two.energies.strain);
  EXPECT_EQ(one.energies.friction, two.energies.friction);
  EXPECT_EQ(one.energies.damping, two.energies.damping);
  std::printf("%zu cracks, %zu touching contacts\n", one.cracks, one.contacts.size());
}

}  // namespace
}  // namespace rbdem
