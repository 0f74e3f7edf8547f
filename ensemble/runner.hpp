#pragma once
// The ensemble runner: many rocks of one scene on all cores. Each rock is released
// (release.hpp), run with the recorders the options ask for (recorders.hpp) on a worker thread,
// and its outcome is passed on (to the raster accumulator and the sink) strictly in rock order on
// the calling thread (ordered_pool.hpp), so every output is bit-identical for any number of
// threads, and only a bounded window of finished rocks is held in memory.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ensemble/evaluation_lines.hpp"
#include "ensemble/outcome.hpp"
#include "ensemble/rasters.hpp"
#include "ensemble/recorders.hpp"
#include "ensemble/release.hpp"
#include "solver/simulate.hpp"

namespace talus::ensemble {

struct EnsembleOptions {
  int threads = 0;  // worker threads; 0: all cores
  // The rocks to run: [first_rock, end_rock) of the release; end_rock < 0: to the last one.
  long first_rock = 0;
  long end_rock = -1;
  long stride = 1;  // run every stride-th rock of that range, from first_rock (a subsample)
  bool trajectories = false;            // record every rock's trajectory
  // Record also the trajectories of the rocks this accepts (e.g. a sample for a picture); empty: none.
  std::function<bool(long rock)> sample_trajectories;
  double trajectory_interval_s = 0.01;  // samples at t = 0, every interval, and the end
  RasterRequest rasters;                // nothing requested: no raster work
  // Where the values behind the percentile rasters are spilled during the run (a directory inside
  // the run's staging directory: removed on success and on failure) and the memory to read them
  // back in (raster_spill.hpp).
  RasterSpillOptions raster_spill;
  // Keep the raster accumulator in the report (EnsembleReport::raster_state) for merging with other
  // runs' instead of finishing the rasters.
  bool keep_raster_state = false;
  bool episodes = false;  // record every rock's contact episodes
  EpisodeOptions episode_options;
  // Record every rock's crossings of these lines (RockOutcome::line_crossings); null or empty: no
  // line work at all.
  std::shared_ptr<const std::vector<EvaluationLine>> evaluation_lines;
  std::vector<RecorderFactory> extra_recorders;  // further per-thread recorders
  // Called on the calling thread with (rocks done, rocks in total), at most every 0.2 s and at the
  // end.
  std::function<void(long, long)> progress;
};

// Receives finished rocks in rock order, on the calling thread.
class RockSink {
 public:
  virtual ~RockSink() = default;
  virtual void OnRock(const RockOutcome& outcome) = 0;
};

struct EnsembleReport {
  long rocks = 0;
  std::array<long, kEndReasons> by_end{};  // indexed by EndReason
  long raised = 0;               // rocks whose start had to be raised above the terrain
  // Rocks whose centre of mass never got further from its start than the rock's length
  // (RockResult::StayedAtRelease): held at release by the ground model, e.g. a slab landing flat
  // where mu(s) exceeds the slope's tangent.
  long stayed_at_release = 0;
  long steps = 0;
  long unconverged_steps = 0;
  int threads = 1;
  double wall_time_s = 0;
  std::vector<RasterLayer> rasters;
  // With EnsembleOptions::keep_raster_state; shared by copies of the report (it owns the spill's
  // files, which are not copied).
  std::shared_ptr<RasterAccumulator> raster_state;

  // Adds the counts of another part of the same ensemble (rasters are merged by the caller).
  void AddCounts(const EnsembleReport& other);

  double trajectories_per_s() const { return wall_time_s > 0 ? double(rocks) / wall_time_s : 0.0; }
  long count(EndReason end) const { return by_end[static_cast<std::size_t>(end)]; }
  std::string BriefReport() const;
};

// The worker threads a run of `total_rocks` rocks uses when `requested` are asked for (0: one per
// core): never more than there are rocks, at least one.
int WorkerThreads(int requested, long total_rocks);

// Runs rocks options.first_rock .. options.end_rock - 1 (all by default). Requires scene.IsValid(),
// release.IsValid() and 0 <= first_rock <= end_rock <= release.total_rocks().
// An exception thrown by the sink stops the workers and is rethrown.
EnsembleReport RunEnsemble(const Scene& scene, const ReleaseSpec& release,
                           const EnsembleOptions& options, RockSink* sink = nullptr);

}  // namespace talus::ensemble
