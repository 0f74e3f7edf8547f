#pragma once
// Small scenes for the ensemble tests: few rocks, small grids, short runs.

#include "ensemble/release.hpp"
#include "solver/scene.hpp"
#include "solver/shapes.hpp"

namespace talus::ensemble::testing {

// A short slope_deg plane (slope_length_m long, then flat) with a 0.4 m cube on medium_hard ground.
inline Scene SmallPlane(double slope_deg, double slope_length_m, double runout_m,
                        double width_m = 20, double cell_m = 1) {
  Scene scene;
  PlaneSpec plane{slope_deg, slope_length_m, runout_m, width_m, cell_m};
  scene.terrain = Terrain(MakePlaneHeightfield(plane), scene.ground.IndexOfName("medium_hard"));
  scene.rock = MakeRockShape(MakeBox(0.4, 0.4, 0.4), 2700);
  scene.options.max_time_s = 8;
  return scene;
}

inline ReleaseSpec PointRelease(const std::vector<Eigen::Vector2d>& points, long rocks) {
  ReleaseSpec spec;
  for (const Eigen::Vector2d& p : points)
    spec.releases.push_back({ReleaseGeometry::Kind::kPoint, {{p}}});
  spec.rocks_per_release = rocks;
  return spec;
}

}  // namespace talus::ensemble::testing
