#pragma once
// Recorders: per-thread observers that watch one rock at a time as it runs and store what they
// saw in its outcome. The runner merges outcomes in rock order, so whatever a recorder produces
// is independent of the number of threads. Rasters, trajectories and contact episodes are
// recorders; a caller can plug in its own (EnsembleOptions::extra_recorders).

#include <functional>
#include <memory>

#include "ensemble/outcome.hpp"
#include "solver/episodes.hpp"
#include "solver/terrain.hpp"

namespace talus::ensemble {

class RockRecorder : public StepObserver {
 public:
  // A rock starts: outcome.rock, release, shape and start are set.
  virtual void Begin(const RockOutcome& outcome) = 0;
  // The rock has ended (outcome.result is set): store what was recorded in the outcome.
  virtual void Finish(RockOutcome& outcome) = 0;
};

// Makes one recorder per worker thread.
using RecorderFactory = std::function<std::unique_ptr<RockRecorder>()>;

// Trajectory samples at t = 0, every interval_s, and the end, for the rocks `wanted` accepts.
std::unique_ptr<RockRecorder> MakeTrajectoryRecorder(double interval_s, double dt_s,
                                                     std::function<bool(long rock)> wanted);

// Contact episodes of every rock (solver/episodes.hpp).
std::unique_ptr<RockRecorder> MakeEpisodeRecorder(const Terrain& terrain,
                                                  const EpisodeOptions& options);

}  // namespace talus::ensemble
