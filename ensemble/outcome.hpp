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
  std::vector<int> tree_hit_cells;  // the cell of the stem of each impact on a stem (tree_hits)
};

// What one rock did at one evaluation line (ensemble/evaluation_lines.hpp): the first crossing of
// its centre of mass, interpolated linearly within the step (time, position, velocity; rotational
// energy between the step's ends; orientation by slerp), and its number of crossings in all.
struct LineCrossing {
  int line = 0;  // index into the scene's evaluation lines
  double t_s = 0;
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // centre of mass, world
  double speed_m_s = 0;                                  // of the centre of mass
  double translational_energy_J = 0;                     // 1/2 m |v|^2
  double rotational_energy_J = 0;                        // 1/2 w . Theta w
  double com_height_m = 0;     // centre of mass above the terrain, vertical
  double bounce_height_m = 0;  // lowest hull vertex above the terrain, vertical; 0 when touching
  long crossings = 0;          // times the centre of mass crossed the line in all
  double energy_J() const { return translational_energy_J + rotational_energy_J; }
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
  // The first crossing of each evaluation line the rock crossed, in line order
  // (ensemble/evaluation_lines.hpp).
  std::vector<LineCrossing> line_crossings;
  // Values callers' own recorders store (EnsembleOptions::extra_recorders), each under its own
  // name and in its own layout.
  std::map<std::string, std::vector<double>> extra;
};

}  // namespace talus::ensemble
