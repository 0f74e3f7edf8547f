#pragma once
// Where and how rocks start: release points, lines and polygons, and the per-rock start state drawn
// from the rock's own random stream (seed, rock index), so that runs are reproducible.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "solver/scene.hpp"
#include "solver/state.hpp"

namespace talus::ensemble {

// One release: a point, a polyline (start points uniform along its length) or a polygon (start
// points uniform over its area; rings after the first are holes). Map coordinates, m.
struct ReleaseGeometry {
  enum class Kind { kPoint, kLine, kPolygon };
  Kind kind = Kind::kPoint;
  std::vector<std::vector<Eigen::Vector2d>> rings;  // point: one ring of one vertex; line: one ring
};

struct ReleaseSpec {
  static constexpr long kMaxTotalRocks = 1'000'000'000;  // rocks in one run, all releases together

  std::vector<ReleaseGeometry> releases;
  long rocks_per_release = 1;
  double height_m = 1.0;  // centre of mass above the ground at release (before any raise)
  // Fixed orientation of the shape as given (w, x, y, z), or nullopt for uniform on SO(3).
  std::optional<Eigen::Quaterniond> orientation;
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();            // world frame
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();  // world frame
  std::uint64_t seed = 1;

  long total_rocks() const { return rocks_per_release * static_cast<long>(releases.size()); }
  int ReleaseOf(long rock) const { return static_cast<int>(rock / rocks_per_release); }
  // False, naming the field and value, when a value is out of range (more than kMaxTotalRocks
  // rocks in all) or a geometry is degenerate (a line of zero length, a polygon whose holes leave
  // no area).
  bool IsValid(std::string* why) const;
};

// A point of `release` where the terrain has no height (outside the DEM or on a nodata cell), or
// nullopt when rocks can start anywhere on it: its vertices, its lines or rings (checked every
// quarter cell) and, for a polygon, the centres of the cells without height that it covers.
std::optional<Eigen::Vector2d> PointOffTerrain(const Terrain& terrain,
                                               const ReleaseGeometry& release);

// The start state of rock `rock` (0-based, releases one after another): position on its release
// with the centre of mass height_m above the ground, orientation, velocities. Not yet raised above
// the terrain (see RaiseAboveTerrain). Depends on (spec.seed, rock) only.
RockState ReleaseState(const Scene& scene, const ReleaseSpec& spec, long rock);

}  // namespace talus::ensemble
