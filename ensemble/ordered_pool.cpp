#include "ensemble/ordered_pool.hpp"

#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

namespace talus::ensemble {

void RunInOrder(long total, const OrderedPoolOptions& options,
                const std::function<std::function<RockOutcome(long)>()>& make_worker,
                const std::function<void(RockOutcome&&)>& merge) {
  using Clock = std::chrono::steady_clock;
  const int threads = options.threads < 1 ? 1 : options.threads;
  // Finished items wait in a ring of `window` slots until every earlier item is merged.
  const long window = OrderedPoolWindow(threads);

  std::mutex mutex;
  std::condition_variable worker_cv, merger_cv;
  std::vector<std::optional<RockOutcome>> ring(static_cast<std::size_t>(window));
  long next_claim = 0, next_merge = 0;
  bool abort = false;
  std::exception_ptr worker_error;

  auto work = [&]() {
    try {
      const std::function<RockOutcome(long)> run = make_worker();
      while (true) {
        long item;
        {
          std::unique_lock lock(mutex);
          worker_cv.wait(lock, [&] {
            return abort || next_claim >= total || next_claim < next_merge + window;
          });
          if (abort || next_claim >= total) return;
          item = next_claim++;
        }
        RockOutcome done = run(item);
        {
          std::lock_guard lock(mutex);
          ring[static_cast<std::size_t>(item % window)] = std::move(done);
        }
        merger_cv.notify_one();
      }
    } catch (...) {
      std::lock_guard lock(mutex);
      if (!worker_error) worker_error = std::current_exception();
      abort = true;
      merger_cv.notify_all();
      worker_cv.notify_all();
    }
  };

  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(threads));
  auto stop = [&]() {
    {
      std::lock_guard lock(mutex);
      abort = true;
    }
    worker_cv.notify_all();
    for (std::thread& t : pool) t.join();
  };
  try {
    for (int k = 0; k < threads; ++k) pool.emplace_back(work);
  } catch (...) {  // a thread could not start: stop and join the ones that did
    stop();
    throw;
  }

  auto last_progress = Clock::now();
  const auto report_progress = [&](long done) {
    if (options.progress && Clock::now() - last_progress > std::chrono::milliseconds(200)) {
      options.progress(done, total);
      last_progress = Clock::now();
    }
  };
  try {
    for (long item = 0; item < total; ++item) {
      RockOutcome done;
      {
        std::unique_lock lock(mutex);
        auto& slot = ring[static_cast<std::size_t>(item % window)];
        while (!slot && !abort) {
          merger_cv.wait_for(lock, std::chrono::milliseconds(200));
          lock.unlock();
          report_progress(item);
          lock.lock();
        }
        if (abort) break;
        done = std::move(*slot);
        slot.reset();
        next_merge = item + 1;
      }
      worker_cv.notify_all();
      merge(std::move(done));
      report_progress(item + 1);
    }
  } catch (...) {
    stop();
    throw;
  }
  stop();
  if (worker_error) std::rethrow_exception(worker_error);
}

}  // namespace talus::ensemble
