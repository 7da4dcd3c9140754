// rbdem shear, direct shear of one joint: the peak against the envelope of the joint's bonds (docs/theory.md,
// section 4.3), the residual against Coulomb sliding at the joint's contact friction, the normal stress of a
// constant normal stiffness test against sigma_n0 + k x dilation, and the scenes it refuses.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <vector>

#include "dem/driver/driver.hpp"
#include "dem/driver/registry.hpp"
#include "dem/laws/parallel_bond.hpp"
#include "dem/specimen_mesh.hpp"
#include "io/checkpoint.hpp"

namespace rbdem {
namespace {

// A 20 mm x 20 mm specimen of the paper's materials with one horizontal joint through its centre, 2 mm blocks on the
// structured mesh rbdem shear asks for (mesh.structured: every joint bond equally stiff).
Scene shear_scene(double normal_stress) {
  Scene s;
  s.specimen.width = s.specimen.height = 0.02;
  s.mesh.size = 0.002;
  s.mesh.structured = true;
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

// Under a constant normal load of 2, 5 and 10 MPa: the boxes slip every joint bond by the same amount, and on the
// structured mesh every joint bond has the same stiffness (k_mean / k_max = 1), so each carries the mean traction
// and all of them reach their strength together, at the bonded interface's envelope c_j + sigma_n tan(phi_j) with
// c_j = 2 c (the sticking linear part carries half the traction): the peak within 5 % of it (and not above it by
// more than the shear's resolution, 1/200 of c_j per step). The residual is within 5 % of mu sigma_n, the normal
// stress held.
TEST(Shear, PeakMeetsTheJointEnvelopeAndResidualTheContactFriction) {
  for (double sn : {2e6, 5e6, 10e6}) {
    const Scene s = shear_scene(sn);
    const TestResult r = run_test("shear", s, make_mesh(s));
    SCOPED_TRACE(testing::Message() << "sigma_n = " << sn);
    ASSERT_TRUE(r.completed);
    EXPECT_EQ(r.test, "shear");
    EXPECT_EQ(r.stop_reason, "max_shear_displacement");
    EXPECT_TRUE(r.quasi_static) << r.quasi_static_reason;
    EXPECT_EQ(r.failure_mode, "shear_slip_along_joints");
    EXPECT_NEAR(r.own_value("joint_stiffness_uniformity"), 1.0, 1e-9);
    const MohrCoulomb env = envelope(s);
    EXPECT_EQ(env.cohesion, 2.0 * s.joint.cohesion);
    const double peak = r.own_value("peak_shear_stress_pa"), closed_form = env.cohesion + sn * env.tan_phi;
    EXPECT_EQ(r.own_value("joint_envelope_peak_pa"), closed_form);
    EXPECT_LE(peak, closed_form + 0.01 * env.cohesion);
    EXPECT_NEAR(peak / closed_form, 1.0, 0.05);
    EXPECT_NEAR(r.own_value("residual_shear_stress_pa") / (s.joint.contact_friction * sn), 1.0, 0.05);
    EXPECT_NEAR(r.own_value("final_normal_stress_pa") / sn, 1.0, 0.01);
    EXPECT_GE(r.own_value("final_shear_displacement_m"), s.loading.max_shear_displacement);
    EXPECT_EQ(r.crack_counts.joint_tensile + r.crack_counts.joint_shear, int(r.joint_bonds));  // the joint let go
    EXPECT_EQ(r.crack_counts.rock_tensile + r.crack_counts.rock_shear, 0);
    EXPECT_GT(r.curve.back().shear_displacement, 0.0);
  }
}

// Whether the servo has settled at a curve point: 50 steps after the last bond broke (it takes up a quarter of the
// load error per step).
bool settled(const TestResult& r, const CurvePoint& p) {
  for (const Crack& c : r.cracks)
    if (c.time <= p.time && c.time > p.time - 50 * r.dt) return false;
  return true;
}

// The points of the curve after the joint's last bond broke and the servo settled: the joint slides as two faces in
// contact.
std::vector<CurvePoint> sliding(const TestResult& r) {
  double last_break = 0;
  for (const Crack& c : r.cracks) last_break = std::max(last_break, c.time);
  std::vector<CurvePoint> out;
  for (const CurvePoint& p : r.curve)
    if (p.time > last_break + 50 * r.dt) out.push_back(p);
  return out;
}

// Patton's dilation under a constant normal load: once the joint slides, every contact across it opens by its slip
// times tan(i) while its forces stay the same (constant normal and shear load: no elastic change), so the upper box
// rises by the box's shear displacement times tan(i), within 2 %; the residual stays mu sigma_n (the law keeps the
// friction coefficient).
TEST(Shear, DilatingJointOpensBySlipTimesTanIUnderConstantNormalLoad) {
  Scene s = shear_scene(5e6);
  s.joint.dilation_deg = 10;
  const double tan_i = std::tan(s.joint.dilation_deg * std::numbers::pi / 180);
  const TestResult r = run_test("shear", s, make_mesh(s));
  ASSERT_TRUE(r.completed);
  const std::vector<CurvePoint> slide = sliding(r);
  ASSERT_GT(slide.size(), 10u);
  const CurvePoint &a = slide.front(), &b = slide.back();
  const double expected = (b.shear_displacement - a.shear_displacement) * tan_i;
  EXPECT_GT(expected, 0.2e-6);  // m: the joint slides some 1.9 um
  EXPECT_NEAR((b.dilation - a.dilation) / expected, 1.0, 0.02);
  EXPECT_GT(r.own_value("dilation_m"), 0.0);  // the joint closed by some 30 nm as its bonds broke, and opened since
  EXPECT_NEAR(r.own_value("final_normal_stress_pa") / 5e6, 1.0, 0.01);
  EXPECT_NEAR(r.own_value("residual_shear_stress_pa") / (s.joint.contact_friction * 5e6), 1.0, 0.05);
}

// Constant normal stiffness: the normal stress is sigma_n0 + k x dilation. The flat joint (i = 0) closes as its bonds
// break (the linear part then carries the whole normal load), so the change is negative, and it holds to 2 % of the
// change wherever the servo has settled. The dilating joint (i = 10 deg) opens as it slides and the normal stress
// rises by k times the dilation, to 2 %, from the first sample of the slide to the last: while the box rises the
// servo trails its load by a constant v K dt / alpha (about 0.03 MPa here, 1.5 % of the final change), which the
// difference leaves out. The residual follows: mu times the normal stress over the same samples.
TEST(Shear, ConstantNormalStiffnessChangesTheNormalStressByKTimesTheDilation) {
  for (const double dilation_deg : {0.0, 10.0}) {
    SCOPED_TRACE(testing::Message() << "joint.dilation_deg = " << dilation_deg);
    Scene s = shear_scene(5e6);
    s.loading.normal_stiffness = 1e13;  // Pa/m: the flat joint's closure of ~0.04 um changes sigma_n by ~0.4 MPa
    s.joint.dilation_deg = dilation_deg;
    const TestResult r = run_test("shear", s, make_mesh(s));
    ASSERT_TRUE(r.completed);
    if (dilation_deg == 0) {
      int checked = 0;
      for (const CurvePoint& p : r.curve) {
        const double change = s.loading.normal_stiffness * p.dilation;
        if (p.shear_displacement <= 0 || std::abs(change) < 0.05 * 5e6 || !settled(r, p)) continue;
        EXPECT_NEAR((p.normal_stress - 5e6) / change, 1.0, 0.02) << "at shear displacement " << p.shear_displacement;
        ++checked;
      }
      EXPECT_GT(checked, 100);
      EXPECT_NEAR((r.own_value("final_normal_stress_pa") - 5e6) / (1e13 * r.own_value("dilation_m")), 1.0, 0.02);
    } else {
      const std::vector<CurvePoint> slide = sliding(r);
      ASSERT_GT(slide.size(), 10u);
      const CurvePoint &a = slide.front(), &b = slide.back();
      EXPECT_GT(b.normal_stress - a.normal_stress, 0.2 * 5e6);  // it rose by some 2 MPa
      EXPECT_NEAR((b.normal_stress - a.normal_stress) / (1e13 * (b.dilation - a.dilation)), 1.0, 0.02);
    }
    // The residual's samples (residual_shear_stress: the last quarter of the shear displacement) against mu sigma_n.
    const double from = 0.75 * r.curve.back().shear_displacement;
    double tau = 0, sigma = 0;
    for (const CurvePoint& p : r.curve)
      if (p.step > 0 && p.shear_displacement > from) tau += p.stress(), sigma += p.normal_stress;
    EXPECT_NEAR(tau / (s.joint.contact_friction * sigma), 1.0, 0.05);
  }
}

// The stage (the normal load coming on, then the shear), the servo with its CNS spring and origin are in the boxes'
// snapshot, the contacts' dilation in the engine's: a run interrupted while the load comes on, before the peak and
// after it, and resumed from its checkpoint file, ends bit for bit as the uninterrupted one.
TEST(Shear, ResumedRunEndsBitIdenticalToUninterrupted) {
  Scene s = shear_scene(5e6);
  s.loading.normal_stiffness = 1e13, s.loading.max_shear_displacement = 1e-6;
  s.joint.dilation_deg = 10;
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
