// rbdem shear, direct shear of one joint: the peak against the envelope of the joint's bonds (docs/theory.md,
// section 4.3), the residual against Coulomb sliding at the joint's contact friction, the normal stress of a
// constant normal stiffness test against sigma_n0 + k x dilation, and the scenes it refuses.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <numbers>

#include "dem/driver/driver.hpp"
#include "dem/driver/registry.hpp"
#include "dem/laws/parallel_bond.hpp"
#include "dem/specimen_mesh.hpp"
#include "io/checkpoint.hpp"

namespace rbdem {
namespace {

// A 20 mm x 20 mm specimen of the paper's materials with one horizontal joint through its centre, 2 mm blocks.
Scene shear_scene(double normal_stress) {
  Scene s;
  s.specimen.width = s.specimen.height = 0.02;
  s.mesh.size = 0.002;
  s.joint_set.dip_deg = 0, s.joint_set.spacing = 1.0, s.joint_set.offset = 0;
  s.loading.normal_stress = normal_stress;
  s.loading.max_shear_displacement = 2e-6;  // the joint has slid into its residual by 0.3 um
  s.numerics.threads = 1;
  return s;
}

// The model's closed form for its joint: the envelope of a bonded interface (c_j, phi_j).
MohrCoulomb envelope(const Scene& s) {
  return interface_envelope(s.joint.cohesion, std::tan(s.joint.friction_deg * std::numbers::pi / 180),
                            s.joint.contact_friction, s.joint.slip_when_bonded);
}

// Under a constant normal load of 2 and 10 MPa: the boxes slip every joint bond by the same amount, so the stiffest
// bond reaches its strength first, at (k_mean / k_max) c_j + sigma_n tan(phi_j), and the peak lies between that and
// the envelope c_j + sigma_n tan(phi_j); on this mesh the joint's bonds are within a few % of one stiffness and the
// peak is within 2 % of the first break and 5 % of the envelope. The residual is within 5 % of mu sigma_n, the
// normal stress held.
TEST(Shear, PeakFollowsTheJointEnvelopeAndResidualTheContactFriction) {
  for (double sn : {2e6, 10e6}) {
    const Scene s = shear_scene(sn);
    const TestResult r = run_test("shear", s, make_mesh(s));
    SCOPED_TRACE(testing::Message() << "sigma_n = " << sn);
    ASSERT_TRUE(r.completed);
    EXPECT_EQ(r.test, "shear");
    EXPECT_EQ(r.stop_reason, "max_shear_displacement");
    EXPECT_TRUE(r.quasi_static) << r.quasi_static_reason;
    EXPECT_EQ(r.failure_mode, "shear_slip_along_joints");
    const double uniformity = r.own_value("joint_stiffness_uniformity");
    ASSERT_GT(uniformity, 0.95);
    const MohrCoulomb env = envelope(s);
    const double peak = r.own_value("peak_shear_stress_pa"), first = uniformity * env.cohesion + sn * env.tan_phi;
    // The bounds of any mesh, first break <= peak <= envelope, to the shear's resolution: a step adds 1/200 of c_j.
    EXPECT_GE(peak, first - 0.01 * env.cohesion);
    EXPECT_LE(peak, env.cohesion + sn * env.tan_phi + 0.01 * env.cohesion);
    EXPECT_NEAR(peak / first, 1.0, 0.02);
    EXPECT_NEAR(r.own_value("peak_shear_stress_pa") / (env.cohesion + sn * env.tan_phi), 1.0, 0.05);
    EXPECT_NEAR(r.own_value("residual_shear_stress_pa") / (s.joint.contact_friction * sn), 1.0, 0.05);
    EXPECT_NEAR(r.own_value("final_normal_stress_pa") / sn, 1.0, 0.01);
    EXPECT_GE(r.own_value("final_shear_displacement_m"), s.loading.max_shear_displacement);
    EXPECT_EQ(r.crack_counts.joint_tensile + r.crack_counts.joint_shear, int(r.joint_bonds));  // the joint let go
    EXPECT_EQ(r.crack_counts.rock_tensile + r.crack_counts.rock_shear, 0);
    EXPECT_GT(r.curve.back().shear_displacement, 0.0);
  }
}

// Constant normal stiffness: the normal stress is sigma_n0 + k x dilation, to 2 % of the change, wherever the servo
// has settled (50 steps after a bond broke: it takes up a quarter of the load error per step). The flat joint closes
// as its bonds break (the linear part then carries the whole normal load), so the change is negative here.
TEST(Shear, ConstantNormalStiffnessChangesTheNormalStressByKTimesTheDilation) {
  Scene s = shear_scene(5e6);
  s.loading.normal_stiffness = 1e13;  // Pa/m: the joint's closure of ~0.04 um changes sigma_n by about 0.4 MPa
  const TestResult r = run_test("shear", s, make_mesh(s));
  ASSERT_TRUE(r.completed);
  const auto settled = [&r](const CurvePoint& p) {
    for (const Crack& c : r.cracks)
      if (c.time <= p.time && c.time > p.time - 50 * r.dt) return false;
    return true;
  };
  int checked = 0;
  for (const CurvePoint& p : r.curve) {
    const double change = s.loading.normal_stiffness * p.dilation;
    if (p.shear_displacement <= 0 || std::abs(change) < 0.05 * 5e6 || !settled(p)) continue;
    EXPECT_NEAR((p.normal_stress - 5e6) / change, 1.0, 0.02) << "at shear displacement " << p.shear_displacement;
    ++checked;
  }
  EXPECT_GT(checked, 100);
  EXPECT_NEAR((r.own_value("final_normal_stress_pa") - 5e6) / (1e13 * r.own_value("dilation_m")), 1.0, 0.02);
  EXPECT_NEAR(r.own_value("residual_shear_stress_pa") / (0.5 * r.own_value("final_normal_stress_pa")), 1.0, 0.05);
}

// The stage (the normal load coming on, then the shear), the servo with its CNS spring and origin are in the boxes'
// snapshot: a run interrupted while the load comes on, before the peak and after it, and resumed from its
// checkpoint file, ends bit for bit as the uninterrupted one.
TEST(Shear, ResumedRunEndsBitIdenticalToUninterrupted) {
  Scene s = shear_scene(5e6);
  s.loading.normal_stiffness = 1e13, s.loading.max_shear_displacement = 1e-6;
  const TriMesh mesh = make_mesh(s);
  const TestResult full = run_test("shear", s, mesh);
  ASSERT_TRUE(full.completed);
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("rbdem_shear_checkpoint_" + std::to_string(::getpid()) + ".h5");
  for (const long at : {10L, 150L, 1000L}) {
    RunOptions cut;
    cut.interrupt_at_step = at;
    cut.checkpoint = [&file](const TestCheckpoint& c) { io::write_checkpoint(file, c); };
    EXPECT_THROW(run_test("shear", s, mesh, cut), RunCancelled);
    const TestCheckpoint ck = io::read_checkpoint(file);
    RunOptions go;
    go.resume = &ck;
    const TestResult r = run_test("shear", s, mesh, go);
    SCOPED_TRACE(testing::Message() << "resumed at step " << at);
    EXPECT_EQ(r.steps, full.steps);
    EXPECT_EQ(r.own_value("peak_shear_stress_pa"), full.own_value("peak_shear_stress_pa"));
    EXPECT_EQ(r.own_value("dilation_m"), full.own_value("dilation_m"));
    EXPECT_EQ(r.own_value("final_normal_stress_pa"), full.own_value("final_normal_stress_pa"));
    ASSERT_EQ(r.curve.size(), full.curve.size());
    for (std::size_t k = 0; k < r.curve.size(); ++k) {
      EXPECT_EQ(r.curve[k].stress_top, full.curve[k].stress_top);
      EXPECT_EQ(r.curve[k].normal_stress, full.curve[k].normal_stress);
    }
    ASSERT_EQ(r.cracks.size(), full.cracks.size());
    EXPECT_EQ(r.frames.back().pose, full.frames.back().pose);
  }
  std::filesystem::remove(file);
}

// Scenes that do not suit a direct shear test are refused with the key to change.
TEST(Shear, RefusesScenesWithoutOneHorizontalJoint) {
  const ProtocolInfo& info = protocol_info("shear");
  const auto refused = [&info](Scene s, const std::string& key) {
    try {
      info.check(s);
    } catch (const SceneError& e) {
      return std::string(e.what()).find(key) != std::string::npos;
    }
    return false;
  };
  Scene s = shear_scene(5e6);
  EXPECT_NO_THROW(info.check(s));
  Scene disc = s;
  disc.specimen.shape = "disc";
  EXPECT_TRUE(refused(disc, "specimen.shape"));
  Scene none = s;
  none.joint_set.enabled = false;
  EXPECT_TRUE(refused(none, "joint_set.enabled"));
  Scene dipping = s;
  dipping.joint_set.dip_deg = 30;
  EXPECT_TRUE(refused(dipping, "joint_set.dip_deg"));
  Scene many = s;
  many.joint_set.spacing = 0.005;
  EXPECT_TRUE(refused(many, "joint_set.spacing"));
  Scene confined = s;
  confined.loading.confining_pressure = 1e6;
  EXPECT_TRUE(refused(confined, "loading.confining_pressure"));
}

}  // namespace
}  // namespace rbdem
