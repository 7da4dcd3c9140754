// common/parallel_map.hpp: every item once, the items started in order, the first exception rethrown after the
// workers stopped, no new item after an exception, and the idle hook once per worker that ran out of items.
#include "common/parallel_map.hpp"

#include <atomic>
#include <chrono>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace {

TEST(ParallelMap, RunsEveryItemOnceAndTheIdleHookPerWorker) {
  for (int threads : {1, 2, 4, 16}) {
    std::vector<std::atomic<int>> runs(100);
    std::atomic<int> idle{0};
    rbdem::parallel_map(runs.size(), threads, [&](std::size_t k) { ++runs[k]; }, [&] { ++idle; });
    for (const auto& r : runs) EXPECT_EQ(r.load(), 1) << threads << " threads";
    EXPECT_EQ(idle.load(), std::min(threads, 100)) << threads << " threads";
  }
}

TEST(ParallelMap, StartsItemsInOrder) {
  std::mutex m;
  std::vector<std::size_t> started;
  rbdem::parallel_map(50, 3, [&](std::size_t k) {
    const std::lock_guard<std::mutex> lock(m);
    started.push_back(k);
  });
  ASSERT_EQ(started.size(), 50u);
  // With three workers an item can be recorded at most two places after a later one.
  for (std::size_t i = 0; i < started.size(); ++i) EXPECT_LE(started[i], i + 2);
}

TEST(ParallelMap, NoItemsCallsTheHookOnce) {
  int idle = 0, runs = 0;
  rbdem::parallel_map(0, 4, [&](std::size_t) { ++runs; }, [&] { ++idle; });
  EXPECT_EQ(runs, 0);
  EXPECT_EQ(idle, 1);
}

TEST(ParallelMap, RethrowsTheFirstExceptionAndStopsHandingOutItems) {
  std::atomic<int> runs{0}, idle{0};
  try {
    rbdem::parallel_map(
        1000, 1,
        [&](std::size_t k) {
          ++runs;
          if (k == 3) throw std::runtime_error("item 3");
        },
        [&] { ++idle; });
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "item 3");
  }
  EXPECT_EQ(runs.load(), 4);  // one worker: items 0 to 3, none after the exception
  EXPECT_EQ(idle.load(), 0);  // it stopped for the exception, not for want of items
  // Several workers: each stops after its current item (1 ms), so far fewer than the 1000 items run.
  runs = 0;
  EXPECT_THROW(rbdem::parallel_map(1000, 4,
                                   [&](std::size_t k) {
                                     ++runs;
                                     if (k == 0) throw std::logic_error("first");
                                     std::this_thread::sleep_for(std::chrono::milliseconds(1));
                                   }),
               std::logic_error);
  EXPECT_LT(runs.load(), 100);
}

}  // namespace
