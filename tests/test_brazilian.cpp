// The 2D Brazilian test between flats (dem/driver/protocols/brazilian.cpp). A coarse disc with narrow flats cracks
// under them before the peak: each such break unloads its platen at once, and the platen forces differ until the
// unloading wave has crossed the disc, at any platen speed. Flats of 20 deg load the same disc as a whole.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "dem/driver/driver.hpp"
#include "dem/specimen_mesh.hpp"
#include "study/calibrate.hpp"

namespace rbdem {
namespace {

// The disc of scenes/calibrate_four_targets.toml's evaluation 2 on its first mesh: the paper's materials with
// E* = 20 GPa and the rock's cohesion 15 % over the paper's, 3 mm blocks (602), layers across the load.
Scene coarse_disc(double contact_arc_deg) {
  Scene s;
  s.specimen.shape = "disc";
  s.specimen.contact_arc_deg = contact_arc_deg;
  s.mesh.size = 0.003;
  s.joint_set.dip_deg = 0;
  s.rock.effective_modulus = 20e9;
  s.joint.effective_modulus = 6.25e9;
  s.rock.cohesion = 8.6365e6;
  s.numerics.threads = 1;
  return s;
}

TEST(Brazilian, NarrowFlatsOfACoarseDiscCrushAndUnloadTheirPlatenAtAnySpeed) {
  Scene s = coarse_disc(10);
  const TriMesh mesh = make_mesh(s);
  const TestResult r = run_test("brazilian", s, mesh);
  s.loading.platen_velocity *= 0.5;
  const TestResult slow = run_test("brazilian", s, mesh);
  for (const TestResult* t : {&r, &slow}) {
    ASSERT_TRUE(t->completed);
    EXPECT_GE(t->own_value("platen_cracks_before_peak"), 1.0);
    EXPECT_FALSE(t->quasi_static);
    EXPECT_EQ(t->own_value("crushed_at_flats"), 1.0);
    EXPECT_NE(t->quasi_static_reason.find("specimen.contact_arc_deg"), std::string::npos) << t->quasi_static_reason;
  }
  // An inertial error halves with the speed; the unloading after a crush does not.
  EXPECT_GT(slow.platen_force_mismatch, 0.75 * r.platen_force_mismatch);
  EXPECT_GT(slow.platen_force_mismatch, 0.05);
}

TEST(Brazilian, FlatsOf20DegLoadACoarseDiscQuasiStatically) {
  const Scene narrow = coarse_disc(10), wide = coarse_disc(20);
  const TestResult crushed = run_test("brazilian", narrow, make_mesh(narrow));
  const TestResult r = run_test("brazilian", wide, make_mesh(wide));
  ASSERT_TRUE(r.completed);
  EXPECT_EQ(r.own_value("platen_cracks_before_peak"), 0.0);
  EXPECT_EQ(r.own_value("crushed_at_flats"), 0.0);
  EXPECT_TRUE(r.quasi_static) << r.quasi_static_reason;
  EXPECT_LE(r.platen_force_mismatch, 0.05);
  // The crush under narrow flats ends the test early: the disc loaded as a whole is stronger.
  EXPECT_GT(r.own_value("tensile_strength_pa"), 1.2 * crushed.own_value("tensile_strength_pa"));
}

// A calibration does not run a crushed disc again slower (a slower platen does not help it): the evaluation is
// flagged as not quasi-static at once, and the log names the flats.
TEST(Brazilian, CalibrationDoesNotSlowACrushedDisc) {
  const auto dir = std::filesystem::temp_directory_path() / ("rbdem_crushed_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "c.toml") << "[calibrate]\nbase = \"" RBDEM_SOURCE_DIR "/scenes/paper.toml\"\n"
                                << "tolerance = 0.5\n[calibrate.set]\n\"mesh.size\" = 0.003\n"
                                << "\"rock.effective_modulus\" = 20e9\n\"joint.effective_modulus\" = 6.25e9\n"
                                << "\"numerics.threads\" = 1\n[[parameter]]\nname = \"c\"\nkeys = [\"rock.cohesion\"]\n"
                                << "start = 8.6365e6\n[[target]]\nquantity = \"tensile_strength\"\nbeta = 0\n"
                                << "value = 3.5e6\n";
  std::string log;
  study::CalibrateOptions o;
  o.workers = 1;
  o.log = [&](const std::string& line) { log += line + "\n"; };
  const auto result = study::calibrate(study::load_calibration(dir / "c.toml"), dir / "out", o);
  ASSERT_EQ(result.history.size(), 1u);
  EXPECT_FALSE(result.history[0].quasi_static);
  EXPECT_FALSE(result.converged);
  EXPECT_NE(log.find("not run again slower"), std::string::npos) << log;
  EXPECT_NE(log.find("specimen.contact_arc_deg"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(dir / "out/eval_00/brazilian/slower_2x"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rbdem
