#pragma once
// Whether a few points dominate a scan's convex hull. Stray returns metres off a rock (dust,
// vegetation, a second object) make a hull many times the rock: 60 of them turned a scan of
// 4.6 m^3 into a hull of 124 m^3. The check compares the hull with the hull of the scan's dense
// core, and looks for points far outside the others' spread.

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

namespace talus::pointclouds {

// The check of one scan. Distances are from the centre, the component-wise median of the points
// (which outliers do not move, unlike their mean).
struct HullCheck {
  // The core: the points within the kCoreQuantile quantile (nearest rank) of the distances.
  static constexpr double kCoreQuantile = 0.95;
  // A few points dominate when the hull's volume is more than kMaxVolumeRatio times the core's,
  // or when a point is farther than kFarFactor core radii from the centre. A clean scan of a
  // convex rock is far from both: its core holds most of the hull (the 5 % of points cut off are
  // the tips), and no point of it is more than about 1.5 core radii out (tested on ellipsoids
  // and boxes up to 4:1, tests/pointclouds/hull_check_test.cpp).
  static constexpr double kMaxVolumeRatio = 2.0;
  static constexpr double kFarFactor = 3.0;

  std::size_t points = 0;
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();  // in the points' frame
  double core_radius_m = 0;    // the kCoreQuantile quantile of the distances to the centre
  double hull_volume_m3 = 0;   // of all points
  double core_volume_m3 = 0;   // of the core; 0 when the core spans no volume
  std::size_t far_points = 0;  // farther than kFarFactor * core_radius_m from the centre
  double farthest_m = 0;       // the largest distance to the centre

  // hull_volume_m3 / core_volume_m3 (infinite for a flat core).
  double VolumeRatio() const;
  bool Dominated() const;
  // One paragraph saying what was found and what to do, naming `source`; "" when not dominated.
  std::string Warning(const std::string& source) const;
};

// Checks the points a hull of volume `hull_volume_m3` was taken from (at least 4).
HullCheck CheckHull(const std::vector<Eigen::Vector3d>& points_m, double hull_volume_m3);

}  // namespace talus::pointclouds
