#include "pointclouds/hull_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "common/error.hpp"
#include "pointclouds/convex_hull.hpp"
#include "solver/polyhedron.hpp"

namespace talus::pointclouds {

double HullCheck::VolumeRatio() const {
  if (core_volume_m3 > 0) return hull_volume_m3 / core_volume_m3;
  return std::numeric_limits<double>::infinity();
}

bool HullCheck::Dominated() const { return VolumeRatio() > kMaxVolumeRatio || far_points > 0; }

std::string HullCheck::Warning(const std::string& source) const {
  if (!Dominated()) return "";
  char text[768];
  std::snprintf(text, sizeof text,
                "%s: a few points dominate the rock's hull: its volume %.4g m3 is %.3g times the "
                "volume of the hull of the %.0f %% of points nearest the centre (%.4g m3, within "
                "%.4g m); %zu of %zu points are more than %.0f times that far out (up to %.4g m). "
                "Stray returns? Clean the scan ([rock] clean = { outlier_neighbours = ..., "
                "outlier_std_ratio = ... }, or talus rock hull --outliers/--outlier-std) and "
                "check the hull with talus rock hull",
                source.c_str(), hull_volume_m3, VolumeRatio(), 100 * kCoreQuantile, core_volume_m3,
                core_radius_m, far_points, points, kFarFactor, farthest_m);
  return text;
}

HullCheck CheckHull(const std::vector<Eigen::Vector3d>& points_m, double hull_volume_m3) {
  HullCheck c;
  c.points = points_m.size();
  c.hull_volume_m3 = hull_volume_m3;
  if (points_m.size() < 4) return c;
  const std::size_t n = points_m.size();
  std::vector<double> values(n);
  for (int k = 0; k < 3; ++k) {
    for (std::size_t i = 0; i < n; ++i) values[i] = points_m[i][k];
    std::nth_element(values.begin(), values.begin() + n / 2, values.end());
    c.centre_m[k] = values[n / 2];
  }
  std::vector<double> distance(n);
  for (std::size_t i = 0; i < n; ++i) distance[i] = (points_m[i] - c.centre_m).norm();
  values = distance;
  // Nearest rank: the smallest distance with at least kCoreQuantile of the points at or below it.
  const auto rank = static_cast<std::size_t>(std::ceil(HullCheck::kCoreQuantile * n)) - 1;
  std::nth_element(values.begin(), values.begin() + rank, values.end());
  c.core_radius_m = values[rank];
  std::vector<Eigen::Vector3d> core;
  core.reserve(rank + 1);
  for (std::size_t i = 0; i < n; ++i) {
    if (distance[i] <= c.core_radius_m) core.push_back(points_m[i]);
    if (distance[i] > HullCheck::kFarFactor * c.core_radius_m) ++c.far_points;
    c.farthest_m = std::max(c.farthest_m, distance[i]);
  }
  try {
    c.core_volume_m3 = ComputeMassProperties(ComputeConvexHull(core, "core"), 1.0).volume_m3;
  } catch (const InputError&) {
    c.core_volume_m3 = 0;  // a flat core: the volume comes from the few points outside it
  }
  return c;
}

}  // namespace talus::pointclouds
