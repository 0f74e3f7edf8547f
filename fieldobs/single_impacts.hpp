#pragma once
// Single impacts as runs and observations (docs/validation.md, "Single impacts"): a table with one
// impact of a known block per row -- its incoming speed (normal and tangential components, or the
// total speed and the impact angle) relative to an effective plane, and what was observed after
// it. Each row becomes a run that starts just above the terrain's tangent plane at a point with
// the incoming velocity, and observations of that run's first contact episode.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "common/csv_table.hpp"
#include "ensemble/release.hpp"
#include "fieldobs/observations.hpp"
#include "solver/terrain.hpp"

namespace talus::fieldobs {

// Which columns a single-impact table's values come from (defaults: the names below).
struct SingleImpactColumns {
  std::string id = "impact_id";  // the run's id
  // The incoming velocity: both components (m/s, normal >= 0 towards the plane, tangential >= 0
  // down the slope), or the total speed (m/s) and the angle between the velocity and the plane
  // (degrees, in (0, 90]). When all four are present, the components are used and the total and
  // angle must agree with them (1 % and 0.5 deg).
  std::string normal_speed = "incoming_normal_speed_mps";
  std::string tangent_speed = "incoming_tangent_speed_mps";
  std::string total_speed = "incoming_total_speed_mps";
  std::string angle = "impact_angle_deg";
  // Optional: the block's angular speed at impact (rad/s) about the axis n x d (n the plane's
  // normal, d the downslope direction): positive is the sense of rolling forward. Empty: no spin.
  std::string angular_speed;
  // Observed outcomes (at least one column): translational energy ratio after / before, and the
  // speed after the impact (m/s). Empty cells are not observed.
  std::string energy_ratio = "energy_ratio";
  std::string speed_out = "outgoing_speed_mps";
  // Observed scar depth (m), against the first contact episode's deepest penetration (a soil
  // category, GroundModel::kLu2019; on hard ground the simulated depth is 0).
  std::string scar_depth = "scar_depth_m";
};

// One row: the incoming state of an impact in the plane's frame.
struct IncomingImpact {
  std::string id;
  double normal_speed_m_s = 0;   // > 0: towards the plane
  double tangent_speed_m_s = 0;  // >= 0: down the slope
  double angular_speed_rad_s = 0;
  std::string where;  // "file:line"
};

// Reads the incoming states of every row. Throws InputError naming the file, line and column for
// a missing column, a non-finite value, a negative speed, an angle outside (0, 90] degrees, no
// normal component, components that disagree with the total speed and angle, an empty or repeated
// id, or a table without rows.
std::vector<IncomingImpact> ReadIncomingImpacts(const CsvTable& table,
                                                const SingleImpactColumns& columns);

// The downslope unit vector of the plane with unit normal `normal` (world frame): the direction of
// steepest descent, or +x on level ground.
Eigen::Vector3d DownslopeDirection(const Eigen::Vector3d& normal);

// The run of one impact at `xy_m` on `terrain` (which must have a height there): velocity
// tangent_speed * d - normal_speed * n and angular velocity angular_speed * (n x d) with n and d
// the terrain's normal and downslope direction at xy_m (world frame), the lowest hull vertex
// clearance_m above the ground below it (ReleaseSpec::HeightReference::kLowestPoint), no fixed
// orientation (uniform on SO(3) per rock) and the given block.
ensemble::ReleaseRun SingleImpactRun(const IncomingImpact& impact, const Terrain& terrain,
                                     const Eigen::Vector2d& xy_m, double clearance_m, int block);

// The observations of every row (energy ratio, speed after, scar depth; rows with empty cells give
// none), as observations of the first contact episode of the row's run.
void ReadSingleImpactOutcomes(const CsvTable& table, const SingleImpactColumns& columns,
                              ObservationSet& out);

}  // namespace talus::fieldobs
