#include "ensemble/runner.hpp"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <stdexcept>
#include <thread>

#include "ensemble/ordered_pool.hpp"

namespace talus::ensemble {
namespace {

// The observer SimulateRock calls: forwards every step to the recorders of one worker thread.
class RecorderSet : public StepObserver {
 public:
  void Add(std::unique_ptr<RockRecorder> recorder) { recorders_.push_back(std::move(recorder)); }
  bool empty() const { return recorders_.empty(); }
  void Begin(const RockOutcome& outcome) {
    for (auto& r : recorders_) r->Begin(outcome);
  }
  void OnStep(const RockState& state, const StepReport& step,
              const TerrainSample& ground) override {
    for (auto& r : recorders_) r->OnStep(state, step, ground);
  }
  void Finish(RockOutcome& outcome) {
    for (auto& r : recorders_) r->Finish(outcome);
  }

 private:
  std::vector<std::unique_ptr<RockRecorder>> recorders_;
};

// The recorders the options ask for, for one worker thread.
RecorderSet MakeRecorders(const Scene& scene, const EnsembleOptions& options) {
  RecorderSet set;
  if (options.rasters.any())
    set.Add(std::make_unique<FootprintRecorder>(options.rasters, scene.terrain));
  if (options.trajectories || options.sample_trajectories) {
    const bool all = options.trajectories;
    const std::function<bool(long)> sample = options.sample_trajectories;
    set.Add(MakeTrajectoryRecorder(options.trajectory_interval_s, scene.options.dt_s,
                                   [all, sample](long rock) { return all || sample(rock); }));
  }
  if (options.episodes) set.Add(MakeEpisodeRecorder(scene.terrain, options.episode_options));
  if (options.evaluation_lines && !options.evaluation_lines->empty())
    set.Add(EvaluationLineRecorders(scene.terrain, options.evaluation_lines)());
  for (const RecorderFactory& make : options.extra_recorders) set.Add(make());
  return set;
}

}  // namespace

std::string EnsembleReport::BriefReport() const {
  char line[320];
  std::snprintf(
      line, sizeof line,
      "%ld rocks in %.2f s on %d threads (%.1f trajectories/s): %ld rest, %ld left the domain, "
      "%ld max time, %ld failed; %ld raised at release, %ld stayed at release",
      rocks, wall_time_s, threads, trajectories_per_s(), count(EndReason::kRest),
      count(EndReason::kLeftDomain), count(EndReason::kMaxTime), count(EndReason::kFailed), raised,
      stayed_at_release);
  // Only a scene with barriers can have rocks stopped by one.
  if (const long n = count(EndReason::kBarrier); n > 0)
    return std::string(line) + "; " + std::to_string(n) + " stopped by barriers";
  return line;
}

int WorkerThreads(int requested, long total_rocks) {
  const int threads =
      requested > 0 ? requested : static_cast<int>(std::thread::hardware_concurrency());
  return static_cast<int>(std::clamp<long>(threads, 1, std::max<long>(total_rocks, 1)));
}

void EnsembleReport::AddCounts(const EnsembleReport& other) {
  rocks += other.rocks;
  for (std::size_t k = 0; k < by_end.size(); ++k) by_end[k] += other.by_end[k];
  raised += other.raised;
  steps += other.steps;
  stayed_at_release += other.stayed_at_release;
  unconverged_steps += other.unconverged_steps;
}

EnsembleReport RunEnsemble(const Scene& scene, const ReleaseSpec& release,
                           const EnsembleOptions& options, RockSink* sink) {
  // Callers check scenes and releases (bad input is reported before any work starts).
  assert(scene.IsValid(nullptr) && "RunEnsemble needs a valid scene");
  assert(release.IsValid(nullptr) && "RunEnsemble needs a valid release");
  const auto t0 = std::chrono::steady_clock::now();
  const long first = options.first_rock;
  const long end = options.end_rock < 0 ? release.total_rocks() : options.end_rock;
  if (first < 0 || end < first || end > release.total_rocks())
    throw std::invalid_argument("RunEnsemble: rocks " + std::to_string(first) + ":" +
                                std::to_string(end) + " are not within the ensemble's " +
                                std::to_string(release.total_rocks()));
  if (options.stride < 1)
    throw std::invalid_argument("RunEnsemble: stride " + std::to_string(options.stride) + " < 1");
  const long stride = options.stride;
  const long total = (end - first + stride - 1) / stride;
  const int threads = WorkerThreads(options.threads, total);

  // Worker side: release, run with the recorders, hand over the outcome.
  auto make_worker = [&]() -> std::function<RockOutcome(long)> {
    auto workspace = std::make_shared<SimulationWorkspace>();
    auto recorders = std::make_shared<RecorderSet>(MakeRecorders(scene, options));
    return [&scene, &release, workspace, recorders, first, stride](long item) {
      const long rock = first + item * stride;
      RockOutcome out;
      out.rock = rock;
      out.release = release.ReleaseOf(rock);
      ReleasedRock released = Release(scene, release, rock);
      assert(released.shape && released.shape->IsValid(nullptr) &&
             std::abs(released.start.orientation.squaredNorm() - 1) <= 1e-12 &&
             "Release gave an invalid shape or a non-unit orientation");
      out.shape = std::move(released.shape);
      out.start = released.start;
      out.lift_m = released.lift_m;
      recorders->Begin(out);
      out.result = SimulateRock(scene, *out.shape, out.start, *workspace,
                                recorders->empty() ? nullptr : recorders.get());
      recorders->Finish(out);
      return out;
    };
  };

  // Calling thread: counts, rasters and the sink, in rock order.
  EnsembleReport report;
  report.threads = threads;
  std::optional<RasterAccumulator> rasters;
  if (options.rasters.any()) rasters.emplace(options.rasters, options.raster_spill);
  auto merge = [&](RockOutcome&& out) {
    ++report.rocks;
    ++report.by_end[static_cast<std::size_t>(out.result.end)];
    if (out.lift_m > 0) ++report.raised;
    if (out.result.StayedAtRelease(*out.shape)) ++report.stayed_at_release;
    report.steps += out.result.steps;
    report.unconverged_steps += out.result.unconverged_steps;
    if (rasters) rasters->Add(out.footprint);
    if (sink) sink->OnRock(out);
  };
  OrderedPoolOptions pool;
  pool.threads = threads;
  pool.progress = options.progress;
  RunInOrder(total, pool, make_worker, merge);

  if (options.progress) options.progress(report.rocks, total);
  if (rasters && options.keep_raster_state)
    report.raster_state = std::make_shared<RasterAccumulator>(std::move(*rasters));
  else if (rasters)
    report.rasters = rasters->Finish(scene.terrain.heights());
  report.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return report;
}

}  // namespace talus::ensemble
