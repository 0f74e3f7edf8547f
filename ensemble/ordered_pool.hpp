#pragma once
// A thread pool that runs items 0 .. n - 1 on worker threads and hands their results to the
// calling thread strictly in item order, holding only a bounded window of finished items. The
// ensemble's determinism across thread counts rests on this ordering.

#include <functional>

#include "ensemble/outcome.hpp"

namespace talus::ensemble {

struct OrderedPoolOptions {
  int threads = 1;  // >= 1
  // Called on the calling thread with (items merged, items in total), at most every 0.2 s.
  std::function<void(long, long)> progress;
};

// How many finished items may wait for an earlier one on `threads` threads (each is held in
// memory until merged).
constexpr long OrderedPoolWindow(int threads) { return 8L * (threads < 1 ? 1 : threads) + 16; }

// Runs work(i) for every i in [0, total): each worker thread first calls make_worker() once (on
// that thread) to get its work function, which may keep per-thread scratch state. merge(outcome)
// is called on the calling thread in order of i. An exception from a worker or from merge stops
// all workers, joins them and is rethrown.
void RunInOrder(long total, const OrderedPoolOptions& options,
                const std::function<std::function<RockOutcome(long)>()>& make_worker,
                const std::function<void(RockOutcome&&)>& merge);

}  // namespace talus::ensemble
