#include "ensemble/runner.hpp"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

namespace talus::ensemble {
namespace {

using Clock = std::chrono::steady_clock;

// Samples the trajectory at the requested interval.
class TrajectoryRecorder {
 public:
  TrajectoryRecorder(const RockShape& rock, double interval_s)
      : rock_(rock), interval_s_(interval_s) {}
  void Begin(const RockState& start, std::vector<TrajectorySample>* out) {
    out_ = out;
    Record(start, false);
    next_t_ = start.time_s + interval_s_;
    last_.reset();
    last_recorded_ = true;
  }
  void OnStep(const RockState& state, const StepReport& step, double dt_s) {
    last_ = state;
    last_contact_ = step.contacts > 0;
    if (state.time_s >= next_t_ - 0.5 * dt_s) {
      Record(state, last_contact_);
      next_t_ += interval_s_;
      last_recorded_ = true;
    } else {
      last_recorded_ = false;
    }
  }
  void End() {
    if (!last_recorded_ && last_) Record(*last_, last_contact_);
  }

 private:
  void Record(const RockState& s, bool contact) {
    TrajectorySample sample;
    sample.t_s = s.time_s;
    sample.position_m = s.position_m;
    sample.orientation = rock_.ShapeOrientation(s.orientation);
    sample.velocity_m_s = s.velocity_m_s;
    sample.angular_velocity_rad_s = s.orientation * s.angular_velocity_rad_s;
    sample.contact = contact;
    sample.scar_m = s.scar_m;
    out_->push_back(sample);
  }
  const RockShape& rock_;
  double interval_s_;
  double next_t_ = 0;
  std::vector<TrajectorySample>* out_ = nullptr;
  std::optional<RockState> last_;
  bool last_contact_ = false;
  bool last_recorded_ = true;
};

// The observer SimulateRock calls: forwards steps to the recorders a run needs.
class Recorders : public StepObserver {
 public:
  Recorders(const Scene& scene, const EnsembleOptions& options)
      : scene_(scene),
        options_(options),
        footprint_(options.rasters, scene.rock),
        trajectory_(scene.rock, options.trajectory_interval_s) {}
  void Begin(RockOutcome& outcome) {
    record_ = options_.trajectories || outcome.rock < options_.sample_trajectories;
    if (options_.rasters.any()) footprint_.Begin(outcome.start, scene_.terrain);
    if (record_) trajectory_.Begin(outcome.start, &outcome.trajectory);
  }
  void OnStep(const RockState& state, const StepReport& step,
              const TerrainSample& ground) override {
    if (options_.rasters.any()) footprint_.OnStep(state, step, ground);
    if (record_) trajectory_.OnStep(state, step, scene_.options.dt_s);
  }
  Footprint End(const RockResult& result) {
    if (record_) trajectory_.End();
    return options_.rasters.any() ? footprint_.Finish(result) : Footprint{};
  }
  bool needed() const { return options_.rasters.any() || record_; }

 private:
  const Scene& scene_;
  const EnsembleOptions& options_;
  FootprintRecorder footprint_;
  TrajectoryRecorder trajectory_;
  bool record_ = false;
};

struct Finished {
  RockOutcome outcome;
  Footprint footprint;
};

}  // namespace

std::string EnsembleReport::BriefReport() const {
  char line[320];
  std::snprintf(
      line, sizeof line,
      "%ld rocks in %.2f s on %d threads (%.1f trajectories/s): %ld rest, %ld left the domain, "
      "%ld max time, %ld failed; %ld raised at release",
      rocks, wall_time_s, threads, trajectories_per_s(), count(EndReason::kRest),
      count(EndReason::kLeftDomain), count(EndReason::kMaxTime), count(EndReason::kFailed), raised);
  return line;
}

EnsembleReport RunEnsemble(const Scene& scene, const ReleaseSpec& release,
                           const EnsembleOptions& options, RockSink* sink) {
  const auto t0 = Clock::now();
  const long total = release.total_rocks();
  int threads =
      options.threads > 0 ? options.threads : static_cast<int>(std::thread::hardware_concurrency());
  threads = static_cast<int>(std::clamp<long>(threads, 1, std::max<long>(total, 1)));
  // Finished rocks wait in a ring of `window` slots until every earlier rock is done.
  const long window = 8L * threads + 16;

  std::mutex mutex;
  std::condition_variable worker_cv, merger_cv;
  std::vector<std::optional<Finished>> ring(static_cast<std::size_t>(window));
  long next_claim = 0, next_merge = 0;
  bool abort = false;
  std::exception_ptr worker_error;

  auto work = [&]() {
    try {
      SimulationWorkspace workspace;
      Recorders recorders(scene, options);
      while (true) {
        long rock;
        {
          std::unique_lock lock(mutex);
          worker_cv.wait(lock, [&] {
            return abort || next_claim >= total || next_claim < next_merge + window;
          });
          if (abort || next_claim >= total) return;
          rock = next_claim++;
        }
        Finished done;
        RockOutcome& out = done.outcome;
        out.rock = rock;
        out.release = release.ReleaseOf(rock);
        out.start = ReleaseState(scene, release, rock);
        out.lift_m = RaiseAboveTerrain(scene, out.start);
        recorders.Begin(out);
        out.result =
            SimulateRock(scene, out.start, workspace, recorders.needed() ? &recorders : nullptr);
        done.footprint = recorders.End(out.result);
        {
          std::lock_guard lock(mutex);
          ring[static_cast<std::size_t>(rock % window)] = std::move(done);
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

  EnsembleReport report;
  report.threads = threads;
  std::optional<RasterAccumulator> rasters;
  if (options.rasters.any()) rasters.emplace(options.rasters);
  auto last_progress = Clock::now();
  try {
    for (long rock = 0; rock < total; ++rock) {
      Finished done;
      {
        std::unique_lock lock(mutex);
        auto& slot = ring[static_cast<std::size_t>(rock % window)];
        while (!slot && !abort) {
          merger_cv.wait_for(lock, std::chrono::milliseconds(200));
          if (options.progress && Clock::now() - last_progress > std::chrono::milliseconds(200)) {
            lock.unlock();
            options.progress(rock, total);
            last_progress = Clock::now();
            lock.lock();
          }
        }
        if (abort) break;
        done = std::move(*slot);
        slot.reset();
        next_merge = rock + 1;
      }
      worker_cv.notify_all();
      const RockOutcome& out = done.outcome;
      ++report.rocks;
      ++report.by_end[static_cast<std::size_t>(out.result.end)];
      if (out.lift_m > 0) ++report.raised;
      report.steps += out.result.steps;
      report.unconverged_steps += out.result.unconverged_steps;
      if (rasters) rasters->Add(done.footprint);
      if (sink) sink->OnRock(out);
      if (options.progress && Clock::now() - last_progress > std::chrono::milliseconds(200)) {
        options.progress(rock + 1, total);
        last_progress = Clock::now();
      }
    }
  } catch (...) {
    stop();
    throw;
  }
  stop();
  if (worker_error) std::rethrow_exception(worker_error);
  if (options.progress) options.progress(report.rocks, total);
  if (rasters) report.rasters = rasters->Finish();
  report.wall_time_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return report;
}

}  // namespace talus::ensemble
