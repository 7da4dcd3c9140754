// The engine's team under contention (dem/team.hpp; docs/performance.md, "Runs side by side"): the team shrinks to
// the cores that other processes leave it, probes a larger size with a growing wait, grows back when the cores are
// free, and no result depends on any of it.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "tests/simulations.hpp"

namespace rbdem {
namespace {

// A clock and per-thread run delays fed to a TeamSize as the engine would: a step every `step` seconds, each
// thread of the team waiting `fraction` of the wall time for a core.
struct Feed {
  TeamSize team;
  double now = 0, step = 0.001;
  std::vector<long long> delay = std::vector<long long>(64, 0);

  explicit Feed(int max_threads, bool adapt = true) : team(max_threads, adapt) {}
  // Runs the steps of `seconds` of wall time with the cores giving the team 1 - fraction of its time.
  void run(double seconds, double fraction) {
    for (double end = now + seconds; now < end;) {
      const int n = team.size();
      const bool sample = team.begin(now, n);
      for (int t = 0; t < n; ++t) {
        delay[std::size_t(t)] += (long long)(fraction * step * 1e9);
        if (sample) team.record(t, delay[std::size_t(t)], 100 + t);
      }
      now += step;
      team.end(now);
    }
  }
};

TEST(Team, KeepsItsSizeOnFreeCores) {
  Feed f(2);
  f.run(5, 0.01);
  EXPECT_EQ(f.team.size(), 2);
  EXPECT_EQ(f.team.counts().shrinks, 0);
  EXPECT_GT(f.team.counts().windows, 50);
  EXPECT_EQ(f.team.counts().smaller_seconds, 0);
}

TEST(Team, ShrinksWithinTwoWindowsWhenTheCoresAreTaken) {
  Feed f(2);
  f.run(0.11, 0.5);  // the first window opens at the first step and ends after 50 ms
  EXPECT_EQ(f.team.size(), 1);
  EXPECT_EQ(f.team.counts().shrinks, 1);
  EXPECT_EQ(f.team.counts().smallest, 1);
  // Sixteen threads that get two thirds of their time keep about eleven after the first window.
  Feed g(16);
  g.run(0.06, 1.0 / 3);
  EXPECT_EQ(g.team.size(), 11);
}

TEST(Team, ProbesWithADoublingWaitAndGrowsBackWhenTheCoresAreFree) {
  Feed f(2);
  f.run(0.2, 0.5);
  ASSERT_EQ(f.team.size(), 1);
  // One thread alone on its core (the other run holds the second): probes at 0.5, 1, 2, 4, 8 and 8 s of waiting
  // fail, each within a window or two, since the probe finds the cores taken.
  long failed = 0;
  std::vector<double> probe_times;
  for (int k = 0; k < 40000 && failed < 6; ++k) {
    const int before = f.team.size();
    f.run(f.step, before == 1 ? 0.0 : 0.5);
    if (before == 1 && f.team.size() == 2) probe_times.push_back(f.now);
    failed = f.team.counts().failed_probes;
  }
  ASSERT_EQ(probe_times.size(), 6u);
  for (std::size_t k = 1; k < probe_times.size(); ++k) {
    const double wait = probe_times[k] - probe_times[k - 1];
    const double expected = std::min(0.5 * double(1 << k), 8.0);
    EXPECT_NEAR(wait, expected, 0.2) << "probe " << k;
  }
  EXPECT_EQ(f.team.size(), 1);
  // The other run ends: the next probe finds the cores free and the team stays at two.
  f.run(10, 0.0);
  EXPECT_EQ(f.team.size(), 2);
  EXPECT_EQ(f.team.counts().probes, 7);
  EXPECT_EQ(f.team.counts().failed_probes, 6);
  EXPECT_NEAR(f.team.counts().smaller_seconds, 0.5 + 1 + 2 + 4 + 8 + 8 + 8, 1.0);  // on one thread between probes
}

TEST(Team, KeepsItsSizeWhenAdaptingIsOffOrTheKernelGivesNoDelays) {
  Feed off(2, false);
  off.run(1, 0.5);
  EXPECT_EQ(off.team.size(), 2);
  EXPECT_EQ(off.team.counts().windows, 0);
  TeamSize blind(2, true);
  for (int k = 0; k < 200; ++k) {
    if (blind.begin(k * 0.001, 2)) blind.record(0, -1, 1), blind.record(1, -1, 2);
    blind.end((k + 1) * 0.001);
  }
  EXPECT_EQ(blind.size(), 2);
  EXPECT_EQ(blind.counts().windows, 0);
}

TEST(Team, ANewKernelThreadRestartsTheWindow) {
  // libgomp may hand a team slot to another kernel thread; its counter starts elsewhere, so the window is not used.
  TeamSize team(2, true);
  ASSERT_TRUE(team.begin(0, 2));
  team.record(0, 0, 1), team.record(1, 0, 2);
  team.end(0.001);
  ASSERT_TRUE(team.begin(0.06, 2));
  team.record(0, 0, 1), team.record(1, 1'000'000'000, 3);  // a second of delay, on a new thread
  team.end(0.061);
  EXPECT_EQ(team.size(), 2);
  EXPECT_EQ(team.counts().windows, 0);
}

// The engine under real contention: busy threads of this process take every core (twice over) while a run with a
// two-thread team steps. Its team must shrink, and its poses must be those of a one-thread run, bit for bit.
TEST(Team, EngineShrinksUnderContentionAndItsResultsDoNotMove) {
  if (thread_run_delay_ns() < 0) GTEST_SKIP() << "the kernel reports no run delays (/proc/thread-self/schedstat)";
  Scene scene;
  scene.mesh.size = 0.003, scene.joint_set.dip_deg = 45;
  const long steps = 1500;
  auto run = [&](int threads, bool contended) {
    scene.numerics.threads = threads;
    auto sim = fixtures::with_platens(scene);
    std::atomic<bool> stop{false};
    std::vector<std::thread> busy;
    if (contended)
      for (unsigned k = 0; k < 2 * std::max(1u, std::thread::hardware_concurrency()); ++k)
        busy.emplace_back([&stop] {
          volatile double x = 0;
          while (!stop.load(std::memory_order_relaxed)) x = x + 1;
        });
    sim->run(steps);
    stop = true;
    for (auto& t : busy) t.join();
    return std::make_pair(sim->pose(), sim->team_counts());
  };
  const auto [alone, alone_counts] = run(1, false);
  const auto [shared, counts] = run(2, true);
  EXPECT_GE(counts.shrinks, 1) << "the team never shrank while every core was taken";
  EXPECT_EQ(counts.smallest, 1);
  EXPECT_GT(counts.contended_seconds, 0);
  EXPECT_EQ(alone, shared) << "the poses moved with the team's size";
  EXPECT_EQ(alone_counts.windows, 0) << "a one-thread run has nothing to adapt";
}

}  // namespace
}  // namespace rbdem
