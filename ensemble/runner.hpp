#pragma once
// The ensemble runner: many rocks of one scene on all cores. Rocks are handed to worker threads
// one at a time; their outcomes are passed on (to the sink and the raster accumulator) strictly in
// rock order on the calling thread, so every output is bit-identical for any number of threads,
// and only a bounded window of finished rocks is held in memory.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "ensemble/rasters.hpp"
#include "ensemble/release.hpp"
#include "solver/simulate.hpp"

namespace talus::ensemble {

// One trajectory sample, in the user's conventions (docs/scenes.md).
struct TrajectorySample {
  double t_s = 0;
  Eigen::Vector3d position_m;      // centre of mass, world
  Eigen::Quaterniond orientation;  // rotation of the shape as given (not the principal frame)
  Eigen::Vector3d velocity_m_s;    // world
  Eigen::Vector3d angular_velocity_rad_s;  // world frame
  bool contact = false;                    // at least one closed contact in the step
  double scar_m = 0;
};

struct EnsembleOptions {
  int threads = 0;                      // worker threads; 0: all cores
  bool trajectories = false;            // record every rock's trajectory
  long sample_trajectories = 0;         // record also the trajectories of rocks 0 .. n - 1
  double trajectory_interval_s = 0.01;  // samples at t = 0, every interval, and the end
  RasterRequest rasters;                // nothing requested: no raster work
  // Called on the calling thread with (rocks done, rocks in total), at most every 0.2 s and at the
  // end.
  std::function<void(long, long)> progress;
};

// Everything known about one finished rock.
struct RockOutcome {
  long rock = 0;
  int release = 0;
  RockState start;    // after any raise above the terrain
  double lift_m = 0;  // how far the start was raised so that no vertex was below ground
  RockResult result;
  std::vector<TrajectorySample> trajectory;  // empty unless recorded (trajectories or the sample)
};

// Receives finished rocks in rock order, on the calling thread.
class RockSink {
 public:
  virtual ~RockSink() = default;
  virtual void OnRock(const RockOutcome& outcome) = 0;
};

struct EnsembleReport {
  long rocks = 0;
  std::array<long, 4> by_end{};  // indexed by EndReason
  long raised = 0;               // rocks whose start had to be raised above the terrain
  long steps = 0;
  long unconverged_steps = 0;
  int threads = 1;
  double wall_time_s = 0;
  std::vector<RasterLayer> rasters;

  double trajectories_per_s() const { return wall_time_s > 0 ? double(rocks) / wall_time_s : 0.0; }
  long count(EndReason end) const { return by_end[static_cast<std::size_t>(end)]; }
  std::string BriefReport() const;
};

// Runs rocks 0 .. release.total_rocks() - 1. Requires scene.IsValid() and release.IsValid().
// An exception thrown by the sink stops the workers and is rethrown.
EnsembleReport RunEnsemble(const Scene& scene, const ReleaseSpec& release,
                           const EnsembleOptions& options, RockSink* sink = nullptr);

}  // namespace talus::ensemble
