// The 3D contact stage (dem/boundary/components3.hpp, BlockContacts3) on the classic check of a block on an
// incline: a tetrahedron resting face-on on a fixed tetrahedron's face tilted by alpha, under its weight. It sticks
// while tan(alpha) < mu and slides once tan(alpha) > mu; the normal force is m g cos(alpha); a flat contact does not
// rattle. The weight is scaled up (g = 1e6 m/s^2) so that the overlap, about 1e-8 m, lies well above the narrow
// phase's coplanarity tolerance (1e-8 of the pair's extent, 1e-10 m here): under its true weight the 2 mm block
// would press the 160 GPa face by 1e-13 m, where the overlap's volume is round-off and the contact is not
// conservative (docs/theory.md 11.9).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "dem/contact3.hpp"
#include "dem/simulation_impl3.hpp"

namespace rbdem {
namespace {

// Weight on the blocks: m g along -z (the engine has no body forces; a component adds them), and a horizontal pull
// along x on block 1 (N).
class Weight : public BoundaryHooks<3> {
 public:
  explicit Weight(double g) : g_(g) {}
  double pull = 0;
  double add_forces(const Model<3>& m, const ModelState<3>&, std::vector<Vec3>& force, std::vector<Vec3>&, double,
                    bool) override {
    for (std::size_t b = 0; b < m.num_blocks(); ++b) force[b].z -= m.body[b].mass * g_;
    force[1].x += pull;
    return 0.0;
  }
  void loads(const Model<3>&, const ModelState<3>&, int, BoundaryLoads&) const override {}
  double work_done() const override { return 0.0; }
  void save(Snapshot&) const override {}
  void load(const Snapshot&, const Model<3>&) override {}

 private:
  double g_;
};

// Two tetrahedra that share no node: a large base below the plane z' = 0 of a frame tilted by alpha about y, and a
// small slider on it, its face in that plane (the slider's face inside the base's face). 10 mm and 2 mm edges.
TetMesh incline(double alpha, bool centred = false) {
  const double c = std::cos(alpha), s = std::sin(alpha);
  auto world = [&](double x, double y, double z) { return std::array<double, 3>{c * x + s * z, y, -s * x + c * z}; };
  TetMesh m;
  const double L = 0.01, a = 0.002, x0 = 0.003, y0 = 0.003;
  m.nodes = {world(0, 0, 0), world(L, 0, 0), world(0, L, 0), world(0, 0, -L),
             world(x0, y0, 0), world(x0 + a, y0, 0), world(x0, y0 + a, 0),
             centred ? world(x0 + a / 3, y0 + a / 3, a) : world(x0, y0, a)};
  m.tets = {{0, 2, 1, 3}, {4, 5, 6, 7}};
  m.layer = {0, 0};
  m.layer_names = {"rock"};
  m.boundary = {{{4, 6, 5}, 1, FaceTag::top}};  // the model wants a top face; no platens are installed
  return m;
}

struct Slide {
  double normal_ratio;  // the contact's normal force over m g cos(alpha), averaged over the last 10 % of the steps
  double spread;        // its largest relative deviation over the last half of the steps
  double travel;        // m, the slider's displacement along the incline over the second half of the steps (the
                        // first half lets the contact settle: the block slides a little while its normal force
                        // builds up from zero)
};

Slide slide(double alpha, double mu, long steps, bool centred = true) {
  const TetMesh mesh = incline(alpha, centred);
  Scene scene;
  scene.rock.contact_friction = mu;
  scene.numerics.threads = 1;
  SimulationImpl<3> sim(scene, mesh);
  const double g = 1e6;
  Weight weight(g);
  sim.engine().attach(&weight);
  sim.engine().fix_block(0);
  const Model<3>& m = sim.engine().model();
  const double kn = m.law[0].modulus / (m.inradius[0] + m.inradius[1]);
  const double area = 0.5 * 0.002 * 0.002;
  sim.set_dt(0.1 * std::sqrt(m.body[1].mass / (kn * area)));
  const double g_normal = m.body[1].mass * g * std::cos(alpha);
  Slide out{0, 0, 0};
  Vec3 start;
  long n_avg = 0;
  for (long k = 0; k < steps; ++k) {
    if (k == steps / 2) start = sim.engine().state().position(1);
    sim.step();
    const ContactStates c = sim.contact_states();
    const double fn = c.size() ? c.normal_force[0] : 0.0;
    if (k > steps / 2) out.spread = std::max(out.spread, std::abs(fn / g_normal - 1.0));
    if (k > steps * 9 / 10) out.normal_ratio += fn / g_normal, ++n_avg;
  }
  out.normal_ratio /= double(std::max(n_avg, 1L));
  const Vec3 d = sim.engine().state().position(1) - start;
  out.travel = d.x * std::cos(alpha) - d.z * std::sin(alpha);  // along +x' (down the incline for alpha > 0)
  return out;
}

// A block settled on a horizontal face under its weight N, then pulled sideways by a force T that grows slowly from
// 0.9 mu N to 1.1 mu N: it holds while T < mu N (only the contact's elastic shear, T / k_s, moves it) and slides
// once T passes mu N. Slip is where its displacement exceeds ten times the elastic one at mu N.
TEST(Contacts3, BlockSlipsWhenThePullReachesMuTimesTheNormalForce) {
  const double mu = 0.5, g = 1e6;
  const TetMesh mesh = incline(0.0, true);
  Scene scene;
  scene.rock.contact_friction = mu;
  scene.numerics.threads = 1;
  SimulationImpl<3> sim(scene, mesh);
  Weight weight(g);
  sim.engine().attach(&weight);
  sim.engine().fix_block(0);
  const Model<3>& m = sim.engine().model();
  const double kn = m.law[0].modulus / (m.inradius[0] + m.inradius[1]);
  sim.set_dt(0.1 * std::sqrt(m.body[1].mass / (kn * 0.5 * 0.002 * 0.002)));
  const double N = m.body[1].mass * g;
  sim.run(20000);  // settle
  const ContactStates settled = sim.contact_states();
  ASSERT_EQ(settled.size(), 1u);
  EXPECT_NEAR(settled.normal_force[0] / N, 1.0, 1e-3);
  const double x0 = sim.engine().state().x[1];
  // The contact's shear stiffness: (k_n / kappa) A_c, A_c the slider's face.
  const double ks = kn / m.law[0].kappa * (0.5 * 0.002 * 0.002);
  const double elastic = mu * N / ks * 10.0;
  const long ramp = 40000;
  double onset = -1;
  for (long k = 0; k <= ramp && onset < 0; ++k) {
    weight.pull = mu * N * (0.9 + 0.2 * double(k) / double(ramp));
    sim.step();
    if (sim.engine().state().x[1] - x0 > elastic) onset = weight.pull;
  }
  ASSERT_GT(onset, 0.0) << "the block never slid";
  EXPECT_NEAR(onset / (mu * N), 1.0, 0.01);
  std::printf("slip onset at T / (mu N) = %.5f\n", onset / (mu * N));
}

// On an incline below the friction angle, resting face-on for 1e5 steps: the normal force is m g cos(alpha) within
// 1 % on average and never strays 1 % from it once settled (no rattle), and the block does not creep.
TEST(Contacts3, FlatContactOnAnInclineDoesNotRattle) {
  const Slide rest = slide(0.2, 0.5, 100000);
  EXPECT_LT(std::abs(rest.travel), 1e-9);
  EXPECT_NEAR(rest.normal_ratio, 1.0, 0.01);
  EXPECT_LT(rest.spread, 0.01) << "the normal force of a block at rest on a face must settle, not rattle";
}

}  // namespace
}  // namespace rbdem
