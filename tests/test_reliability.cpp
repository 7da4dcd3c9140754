// Reliability of a UCS run (docs/reliability.md, "Checkpoints, watchdog and hard cases"): a run resumed from a
// checkpoint ends bit for bit like an uninterrupted one, the same inputs give the same summary at any thread count,
// the watchdog stops an unstable run without a plausible number, and file writers report a full disk.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <unistd.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"
#include "dem/driver/monitors.hpp"
#include "dem/driver/driver.hpp"
#include "tests/simulations.hpp"
#include "io/checkpoint.hpp"
#include "io/result_h5.hpp"
#include "io/results.hpp"

namespace rbdem {
namespace {

namespace fs = std::filesystem;

// 10 x 20 mm specimen, 2 mm mesh, two joints: about 130 blocks, fails in well under a second.
Scene small_scene() {
  Scene s;
  s.specimen.width = 0.01, s.specimen.height = 0.02;
  s.joint_set.spacing = 0.006, s.joint_set.dip_deg = 60;
  s.mesh.size = 0.002;
  s.numerics.threads = 1;
  return s;
}

// summary.json without what may differ between identical runs: the wall time (and, where asked, the thread count).
std::string comparable(nlohmann::json j, bool drop_threads = false) {
  j.erase("wall_seconds");
  j.erase("threads");  // how the run was executed, like its wall time, not what it computed
  if (drop_threads) j["scene"]["numerics"].erase("threads");
  return j.dump(1);
}

fs::path scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / fmt::format("rbdem_rel_{}_{}", name, ::getpid());
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

// The same with softening bonds (docs/model.md, "Softening bonds"): their damage is state a checkpoint must keep.
// 0.5 and 0.3 J/m^2 are 2.5 times what the 2-mm bonds store at their strength.
Scene softening_scene() {
  Scene s = small_scene();
  s.rock.fracture_energy = 0.5, s.joint.fracture_energy = 0.3;
  return s;
}

void expect_resumed_run_bit_identical(const Scene& scene) {
  const TriMesh mesh = make_mesh(scene);
  const TestResult full = run_test("ucs", scene, mesh);
  ASSERT_TRUE(full.completed);
  ASSERT_GT(full.crack_counts.total(), 0);
  const fs::path dir = scratch("resume");
  const fs::path file = dir / "checkpoint.h5";
  // Interrupt at several points: early (before any crack), mid-way and late (after the peak).
  for (const double at : {0.1, 0.5, 0.9}) {
    RunOptions cut;
    cut.interrupt_at_step = std::max(1L, long(at * double(full.steps)));
    cut.checkpoint = [&](const TestCheckpoint& c) { io::write_checkpoint(file, c); };
    try {
      run_test("ucs", scene, mesh, cut);
      FAIL() << "the run was not interrupted at step " << cut.interrupt_at_step;
    } catch (const RunCancelled& c) {
      EXPECT_EQ(c.step, cut.interrupt_at_step);
      EXPECT_TRUE(c.checkpointed);
    }
    const TestCheckpoint ck = io::read_checkpoint(file);
    EXPECT_EQ(ck.steps(), cut.interrupt_at_step);
    for (const int threads : {1, 2}) {
      Scene resumed_scene = scene;
      resumed_scene.numerics.threads = threads;
      TestCheckpoint ck2 = ck;
      ck2.scene_toml = to_toml(resumed_scene);  // the thread count is no part of the physics
      RunOptions go;
      go.resume = &ck2;
      const TestResult r = run_test("ucs", resumed_scene, mesh, go);
      EXPECT_EQ(comparable(io::run_summary(scene, r)), comparable(io::run_summary(scene, full)))
          << "resumed at " << cut.interrupt_at_step << " with " << threads << " threads";
      ASSERT_EQ(r.curve.size(), full.curve.size());
      for (std::size_t k = 0; k < r.curve.size(); ++k) {
        EXPECT_EQ(r.curve[k].stress_top, full.curve[k].stress_top);
        EXPECT_EQ(r.curve[k].kinetic, full.curve[k].kinetic);
      }
      ASSERT_EQ(r.cracks.size(), full.cracks.size());
      for (std::size_t k = 0; k < r.cracks.size(); ++k) EXPECT_EQ(r.cracks[k].time, full.cracks[k].time);
      ASSERT_EQ(r.frames.size(), full.frames.size());
      EXPECT_EQ(r.frames.back().pose, full.frames.back().pose);
    }
  }
  fs::remove_all(dir);
}

TEST(Checkpoint, ResumedRunEndsBitIdenticalToUninterrupted) { expect_resumed_run_bit_identical(small_scene()); }
TEST(Checkpoint, ResumedSofteningRunEndsBitIdenticalToUninterrupted) {
  expect_resumed_run_bit_identical(softening_scene());
}

// The faster platen of quiet spells (loading.fast_factor): its speed is engine state, the time of the last break is
// in the crack log, so a resumed run goes on at the speed the uninterrupted one had.
TEST(Checkpoint, ResumedRunWithAFastPlatenEndsBitIdenticalToUninterrupted) {
  Scene s = small_scene();
  s.loading.fast_factor = 4, s.loading.quiet_transits = 0.2;  // this specimen is quiet for a few transits at a time
  const TriMesh mesh = make_mesh(s);
  ASSERT_LT(run_test("ucs", s, mesh).steps, run_test("ucs", small_scene(), mesh).steps) << "the platen never went faster";
  expect_resumed_run_bit_identical(s);
}

// The platen that follows the rock's state (loading.quiet_breaks, ramp_force_fraction, mismatch_stop): its speed is
// engine state and its rule reads only the crack log and the platen forces of the step, so a resumed run goes on at
// the uninterrupted one's speed, at one thread or two.
TEST(Checkpoint, ResumedRunWithAPlatenThatFollowsTheRockEndsBitIdenticalToUninterrupted) {
  Scene s = small_scene();
  s.rock.weibull_modulus = s.joint.weibull_modulus = 1.5;  // breaks from low load on: every branch of the rule
  s.loading.fast_factor = 3, s.loading.quiet_transits = 0.5, s.loading.quiet_breaks = 1;
  s.loading.ramp_force_fraction = 0.05, s.loading.mismatch_stop = 0.03;
  const TriMesh mesh = make_mesh(s);
  Scene constant = s;
  constant.loading.fast_factor = 1, constant.loading.mismatch_stop = 0;
  ASSERT_NE(run_test("ucs", s, mesh).steps, run_test("ucs", constant, mesh).steps) << "the platen kept its speed";
  expect_resumed_run_bit_identical(s);
}

TEST(Checkpoint, ResumeWithAnotherSceneIsRefused) {
  Scene scene = small_scene();
  const TriMesh mesh = make_mesh(scene);
  TestCheckpoint ck;
  RunOptions cut;
  cut.interrupt_at_step = 50;
  cut.checkpoint = [&](const TestCheckpoint& c) { ck = c; };
  EXPECT_THROW(run_test("ucs", scene, mesh, cut), RunCancelled);
  scene.rock.cohesion *= 1.1;
  RunOptions go;
  go.resume = &ck;
  EXPECT_THROW(run_test("ucs", scene, mesh, go), SceneError);
}

TEST(Determinism, SameInputsGiveBitIdenticalSummaryAtOneAndTwoThreads) {
  for (Scene scene : {small_scene(), softening_scene()}) {
    SCOPED_TRACE(scene.rock.fracture_energy > 0 ? "softening bonds" : "brittle bonds");
    const TriMesh mesh = make_mesh(scene);
    const std::string a = comparable(io::run_summary(scene, run_test("ucs", scene, mesh)), true);
    const std::string b = comparable(io::run_summary(scene, run_test("ucs", scene, mesh)), true);
    scene.numerics.threads = 2;
    const std::string c = comparable(io::run_summary(scene, run_test("ucs", scene, mesh)), true);
    EXPECT_EQ(a, b) << "two runs with the same inputs differ";
    EXPECT_EQ(a, c) << "1 and 2 threads differ";
  }
}

// A sweep hands idle cores to the runs still going (study.cpp): a thread count that changes during the run must
// not change its result either.
TEST(Determinism, ThreadCountChangingDuringTheRunGivesTheSameSummary) {
  Scene scene = small_scene();
  scene.numerics.checkpoint_every_steps = 25;  // the hook that switches the count (nothing is written)
  const TriMesh mesh = make_mesh(scene);
  const std::string one = comparable(io::run_summary(scene, run_test("ucs", scene, mesh)), true);
  scene.numerics.threads = 2;  // the cap; the budget below switches between 1 and 2
  std::atomic<int> budget{1};
  int switches = 0;
  RunOptions o;
  o.thread_budget = &budget;
  o.checkpoint = [&](const TestCheckpoint&) { budget = 3 - budget, ++switches; };
  const std::string changing = comparable(io::run_summary(scene, run_test("ucs", scene, mesh, o)), true);
  EXPECT_GE(switches, 2) << "the thread count never changed during the run";
  EXPECT_EQ(one, changing);
}

// A saving of docs/performance.md, switched off by `off` (the scene key `key`), must give the same run, bit for
// bit. The paper's specimen at 3 mm and 45 deg (0.2 s per run) breaks bonds in shear under compression.
void expect_saving_changes_nothing(const std::string& key, const std::function<void(Scene&)>& off) {
  Scene scene;
  scene.mesh.size = 0.003, scene.joint_set.dip_deg = 45, scene.numerics.threads = 1;
  const TriMesh mesh = make_mesh(scene);
  const TestResult on = run_test("ucs", scene, mesh);
  nlohmann::json a = io::run_summary(scene, on);
  off(scene);
  const TestResult without = run_test("ucs", scene, mesh);
  nlohmann::json b = io::run_summary(scene, without);
  ASSERT_GT(on.crack_counts.total(), 0);
  a["scene"]["numerics"].erase(key), b["scene"]["numerics"].erase(key);
  EXPECT_EQ(comparable(a), comparable(b));
  ASSERT_EQ(on.curve.size(), without.curve.size());
  for (std::size_t k = 0; k < on.curve.size(); ++k) EXPECT_EQ(on.curve[k].stress_top, without.curve[k].stress_top);
}

// Saving (b): the narrow phase of a pair still joined by its bond is wasted work, the bond's linear part being its
// contact. The bonds that break in shear hand their linear part's shear force to the pair's contact: without that
// hand-over the two runs part after a few hundred steps.
TEST(Savings, SkippingTheNarrowPhaseOfBondedPairsChangesNothing) {
  expect_saving_changes_nothing("skip_bonded_pairs", [](Scene& s) { s.numerics.skip_bonded_pairs = false; });
}

// Saving (d): after bond breaks the contact lists are updated, not rebuilt (the engine-level test is
// BroadPhase.UpdatingTheListsAfterBreaksGivesTheRebuildsNumbersToTheBit).
TEST(Savings, UpdatingTheContactListsAfterBreaksChangesNothing) {
  expect_saving_changes_nothing("update_after_breaks", [](Scene& s) { s.numerics.update_after_breaks = false; });
}

TEST(Watchdog, UnstableStepStopsTheRunWithoutAPlausibleNumber) {
  Scene scene = small_scene();
  scene.numerics.dt_safety = 3.0;  // three times the exact stability limit
  const TriMesh mesh = make_mesh(scene);
  const TestResult r = run_test("ucs", scene, mesh);
  EXPECT_FALSE(r.completed);
  EXPECT_FALSE(r.watchdog_cause.empty());
  EXPECT_NE(r.watchdog_message.find("numerics.dt_safety"), std::string::npos) << r.watchdog_message;
  EXPECT_NE(r.watchdog_message.find(fmt::format("step {}", r.watchdog_step)), std::string::npos);
  for (const auto& p : r.curve) {  // what is kept is the last sound state
    EXPECT_TRUE(std::isfinite(p.stress_top) && std::isfinite(p.kinetic)) << "step " << p.step;
    EXPECT_LT(p.step, r.watchdog_step);
  }
  const nlohmann::json j = io::run_summary(scene, r);
  EXPECT_EQ(j["completed"], false);
  EXPECT_TRUE(j["peak_stress_pa"].is_null());
  EXPECT_TRUE(j["youngs_modulus_pa"].is_null());
  EXPECT_EQ(j["watchdog"]["cause"], r.watchdog_cause);
  EXPECT_EQ(j["stop_reason"], "watchdog");
}

TEST(Watchdog, InjectedNanAndEnergyFromNowhereAreCaught) {
  const Scene scene = small_scene();
  const auto sim = fixtures::with_platens(scene);
  sim->run(10);
  std::string detail;
  double ratio = 0;
  WatchdogCriterion c;
  c.floor = 0.5 * scene.rock.effective_modulus * 1e-10 * scene.specimen.width * scene.specimen.height;
  EXPECT_EQ(watchdog_check(*sim, 0.0, c, detail, ratio), "");
  sim->engine().edit([](ModelState<2>& s) { s.vx[3] = 10.0; });  // kinetic energy no work put in
  EXPECT_EQ(watchdog_check(*sim, 0.0, c, detail, ratio), "energy_growth");
  EXPECT_NE(detail.find("exceeds"), std::string::npos);
  sim->engine().edit([](ModelState<2>& s) { s.omega[5] = std::nan(""); });
  EXPECT_EQ(watchdog_check(*sim, 0.0, c, detail, ratio), "non_finite_state");
  EXPECT_NE(detail.find("block 5"), std::string::npos);
}

TEST(Watchdog, SoundRunStaysFarBelowTheLimit) {
  const Scene scene = small_scene();
  const TriMesh mesh = make_mesh(scene);
  const TestResult r = run_test("ucs", scene, mesh);
  EXPECT_TRUE(r.completed);
  EXPECT_GT(r.energy_ratio_max, 0.0);
  EXPECT_LT(r.energy_ratio_max, 1.3) << "a sound run stays well below the 1.5 limit";
}

TEST(Files, FullDiskIsReportedNotTruncated) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const std::string big(1 << 20, 'x');
  try {
    io::write_file_checked("/dev/full", big);
    FAIL() << "writing to /dev/full did not fail";
  } catch (const std::runtime_error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("/dev/full"), std::string::npos) << m;
    EXPECT_NE(m.find("disk full"), std::string::npos) << m;
  }
}

TEST(Files, UnwritableOutputFolderIsNamed) {
  const fs::path dir = scratch("unwritable");
  io::write_file_checked(dir / "a_file", "x");
  try {
    io::require_writable_dir(dir / "a_file" / "out");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "a_file" / "out").string()), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(io::require_writable_dir(dir / "fine"));
  EXPECT_TRUE(fs::is_empty(dir / "fine"));  // the probe is gone
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rbdem
