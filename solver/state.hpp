#pragma once
// The per-rock state a step reads and writes, kept small.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace talus {

struct RockState {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();              // centre of mass, world
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();   // principal frame -> world
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();            // centre of mass, world
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();  // principal (body) frame
  double scar_m = 0;                                                 // scar length s >= 0
  double time_s = 0;
  double rest_timer_s = 0;  // how long the rock has been below the rest thresholds
  int scar_ground = -1;     // ground index of the last loaded contact (its beta decays the scar)
  // Scarring soil (Lu et al. 2019): while part of the hull is in a soil layer, the category where
  // it entered (-1 outside) and the depth of the rebound plane below the surface, set by eq. 11
  // from the vertical speed at entry and kept until the rock has left the layer entirely.
  int soil_ground = -1;
  double soil_depth_m = 0;
};

}  // namespace talus
