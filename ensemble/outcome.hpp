#pragma once
// Everything known about one finished rock, as the ensemble hands it on in rock order.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "solver/episodes.hpp"
#include "solver/polyhedron.hpp"
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

// One rock's footprint on a raster grid: each passed cell once, with the rock's maxima there.
struct Footprint {
  std::vector<int> cells;                                 // j * nx + i
  std::vector<float> speed_m_s, energy_j, jump_height_m;  // parallel to cells, when requested
  int deposit_cell = -1;  // cell of the rest position, -1 when the rock did not come to rest there
};

struct RockOutcome {
  long rock = 0;
  int release = 0;                         // index of its release geometry or run
  std::shared_ptr<const RockShape> shape;  // the shape it ran with
  RockState start;                         // after any raise above the terrain
  double lift_m = 0;  // how far the start was raised so that no vertex was below ground
  RockResult result;  // ending, extremes, runout
  // Filled by the recorders a run asked for, empty otherwise.
  std::vector<TrajectorySample> trajectory;
  std::vector<ContactEpisode> episodes;
  Footprint footprint;
  // Values callers' own recorders store (EnsembleOptions::extra_recorders), each under its own
  // name and in its own layout.
  std::map<std::string, std::vector<double>> extra;
};

}  // namespace talus::ensemble
