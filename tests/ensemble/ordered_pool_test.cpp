#include "ensemble/ordered_pool.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

namespace talus::ensemble {
namespace {

// A work function whose items take uneven times (later items often finish first), recording the
// item in RockOutcome::rock.
std::function<std::function<RockOutcome(long)>()> UnevenWork() {
  return [] {
    return [](long item) {
      std::this_thread::sleep_for(std::chrono::microseconds((item * 7919) % 13 * 100));
      RockOutcome out;
      out.rock = item;
      return out;
    };
  };
}

TEST(OrderedPool, MergesEveryItemOnceInItemOrderForAnyThreadCount) {
  for (int threads : {1, 2, 3, 8}) {
    OrderedPoolOptions options;
    options.threads = threads;
    std::vector<long> merged;
    const std::thread::id caller = std::this_thread::get_id();
    bool merged_on_caller = true;
    RunInOrder(200, options, UnevenWork(), [&](RockOutcome&& out) {
      merged.push_back(out.rock);
      merged_on_caller = merged_on_caller && std::this_thread::get_id() == caller;
    });
    ASSERT_EQ(merged.size(), 200u) << threads;
    for (long k = 0; k < 200; ++k) ASSERT_EQ(merged[static_cast<std::size_t>(k)], k) << threads;
    EXPECT_TRUE(merged_on_caller);
  }
}

TEST(OrderedPool, NoItemsMergesNothing) {
  OrderedPoolOptions options;
  options.threads = 4;
  int merges = 0;
  RunInOrder(0, options, UnevenWork(), [&](RockOutcome&&) { ++merges; });
  EXPECT_EQ(merges, 0);
}

TEST(OrderedPool, EachWorkerThreadMakesItsWorkFunctionOnceOnItself) {
  OrderedPoolOptions options;
  options.threads = 3;
  std::mutex mutex;
  std::multiset<std::thread::id> makers;
  std::set<std::thread::id> runners;
  const std::thread::id caller = std::this_thread::get_id();
  RunInOrder(
      50, options,
      [&] {
        std::lock_guard lock(mutex);
        makers.insert(std::this_thread::get_id());
        return [&](long item) {
          std::lock_guard inner(mutex);
          runners.insert(std::this_thread::get_id());
          RockOutcome out;
          out.rock = item;
          return out;
        };
      },
      [](RockOutcome&&) {});
  EXPECT_EQ(makers.size(), 3u);
  EXPECT_EQ(std::set<std::thread::id>(makers.begin(), makers.end()).size(), 3u);
  EXPECT_EQ(makers.count(caller), 0u);
  for (const std::thread::id& id : runners) EXPECT_EQ(makers.count(id), 1u);
}

// Item 0 is slow: nothing after it may be merged before it, and the workers may not run ahead of
// it by more than the window, so at most that many finished items are held in memory.
TEST(OrderedPool, WorkersRunAheadOfTheOldestUnmergedItemByAtMostTheWindow) {
  OrderedPoolOptions options;
  options.threads = 2;
  const long window = OrderedPoolWindow(options.threads);
  std::atomic<long> highest_started{-1};
  std::atomic<bool> first_done{false};
  long highest_while_first_ran = -1;
  RunInOrder(
      window * 3, options,
      [&] {
        return [&](long item) {
          long seen = highest_started.load();
          while (item > seen && !highest_started.compare_exchange_weak(seen, item)) {
          }
          if (item == 0) {
            // Let the other worker run as far ahead as it may.
            std::this_thread::sleep_for(std::chrono::milliseconds(300));
            highest_while_first_ran = highest_started.load();
            first_done = true;
          }
          RockOutcome out;
          out.rock = item;
          return out;
        };
      },
      [&](RockOutcome&& out) {
        if (out.rock > 0) {
          EXPECT_TRUE(first_done.load());
        }
      });
  EXPECT_LE(highest_while_first_ran, window - 1);  // items 0 .. window - 1 only
  EXPECT_GT(highest_while_first_ran, 0);           // but those do run meanwhile
}

TEST(OrderedPoolWindow, GrowsWithTheThreadsAndHasAFloor) {
  EXPECT_EQ(OrderedPoolWindow(1), 24);
  EXPECT_EQ(OrderedPoolWindow(4), 48);
  EXPECT_EQ(OrderedPoolWindow(0), 24);
}

TEST(OrderedPool, AWorkerExceptionStopsTheRunAndIsRethrown) {
  OrderedPoolOptions options;
  options.threads = 2;
  std::atomic<long> ran{0};
  long merged = 0;
  EXPECT_THROW(RunInOrder(
                   10000, options,
                   [&] {
                     return [&](long item) {
                       ++ran;
                       if (item == 30) throw std::runtime_error("rock 30 failed");
                       RockOutcome out;
                       out.rock = item;
                       return out;
                     };
                   },
                   [&](RockOutcome&&) { ++merged; }),
               std::runtime_error);
  EXPECT_LE(merged, 30);                                 // never past the failed item
  EXPECT_LT(ran.load(), 30 + OrderedPoolWindow(2) + 2);  // the workers stopped
}

TEST(OrderedPool, AMergeExceptionStopsTheWorkersAndIsRethrown) {
  OrderedPoolOptions options;
  options.threads = 2;
  std::atomic<long> ran{0};
  try {
    RunInOrder(
        10000, options,
        [&] {
          return [&](long item) {
            ++ran;
            RockOutcome out;
            out.rock = item;
            return out;
          };
        },
        [&](RockOutcome&& out) {
          if (out.rock == 5) throw std::logic_error("sink full");
        });
    ADD_FAILURE() << "no exception";
  } catch (const std::logic_error& e) {
    EXPECT_STREQ(e.what(), "sink full");
  }
  EXPECT_LT(ran.load(), 6 + OrderedPoolWindow(2) + 2);
}

TEST(OrderedPool, ProgressCountsOnlyMergedItems) {
  OrderedPoolOptions options;
  options.threads = 2;
  long last_done = -1, calls = 0;
  long merged = 0;
  bool sane = true;
  options.progress = [&](long done, long total) {
    sane = sane && total == 40 && done <= merged && done >= last_done;
    last_done = done;
    ++calls;
  };
  RunInOrder(
      40, options,
      [] {
        return [](long item) {
          std::this_thread::sleep_for(std::chrono::milliseconds(15));
          RockOutcome out;
          out.rock = item;
          return out;
        };
      },
      [&](RockOutcome&&) { ++merged; });
  EXPECT_TRUE(sane);
  EXPECT_GE(calls, 1);  // 40 x 15 ms on 2 threads: about 0.3 s, past the first 0.2 s
}

}  // namespace
}  // namespace talus::ensemble
