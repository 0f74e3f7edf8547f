#include "scenes/scenes.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "solver/shapes.hpp"
#include "solver/simulate.hpp"

namespace talus::scenes {

RockShape Eota221() {
  const double density = 2500, mass = 780;
  const double a = 0.93, c = 0.47;
  const double bevel = BevelForVolume(a, a, c, mass / density);
  return MakeRockShape(MakeBevelledBox(a, a, c, bevel), density);
}

Scene Ramp40() {
  PlaneSpec plane;  // defaults are the benchmark ramp
  Scene scene;
  scene.terrain = Terrain(MakePlaneHeightfield(plane), scene.ground.IndexOfName("medium_hard"));
  scene.rock = Eota221();
  return scene;
}

ensemble::ReleaseSpec Ramp40ReleaseSpec(std::uint64_t seed, long rocks) {
  ensemble::ReleaseSpec spec;
  spec.releases.push_back({ensemble::ReleaseGeometry::Kind::kPoint, {{{10.0, 0.0}}}});
  spec.rocks_per_release = rocks;
  spec.height_m = 1.0;
  spec.seed = seed;
  return spec;
}

RockState Ramp40Release(const Scene& ramp, std::uint64_t seed, std::uint64_t rock_index) {
  const long rock = static_cast<long>(rock_index);
  return ensemble::Release(ramp, Ramp40ReleaseSpec(seed, rock + 1), rock).start;
}

}  // namespace talus::scenes

namespace talus::scenes {

Scene Incline(double slope_deg, const RockShape& rock, const GroundParams& ground, double length_m,
              double cell_m) {
  PlaneSpec plane;
  plane.slope_deg = slope_deg;
  plane.slope_length_m = length_m;
  plane.runout_m = 0;
  plane.width_m = length_m;
  plane.cell_m = cell_m;
  Scene scene;
  const int test = scene.ground.Set({"test", 100, ground});
  scene.terrain = Terrain(MakePlaneHeightfield(plane), test);
  scene.rock = rock;
  return scene;
}

}  // namespace talus::scenes

namespace talus::scenes {

const std::array<Lu2019Impact, 4>& Lu2019Impacts() {
  static const std::array<Lu2019Impact, 4> impacts = {{
      {5.56, -14.62, -11.20, 23.85, 0.13, 1.40, 25, 4.0, 0.14, 1.80},
      {5.30, -12.70, -10.74, 26.30, 0.15, 1.80, 15, 1.5, 0.16, 1.64},
      {5.34, -12.31, -10.36, 29.33, 0.18, 1.55, 10, 0.1, 0.18, 1.26},
      {5.34, -14.19, -8.52, 28.69, 0.21, 1.52, 10, 0.5, 0.18, 1.77},
  }};
  return impacts;
}

Scene Lu2019ImpactScene(int i, double slope_deg) {
  const Lu2019Impact& impact = Lu2019Impacts()[i];
  GroundParams soil{0.55, 2.0, 185, 3.0, 0.0};
  soil.model = GroundModel::kLu2019;
  soil.soil_strength_mn_m2 = impact.soil_strength_mn_m2;
  soil.compaction_drag = impact.compaction_drag;
  Scene scene = Incline(slope_deg, Eota221(), soil, 60, 0.5);
  scene.options.max_time_s = 1.0;  // the paper's single-impact runs
  return scene;
}

RockState Lu2019ImpactStart(const Scene& scene, int i, double slope_deg, double angle_rad) {
  const Lu2019Impact& impact = Lu2019Impacts()[i];
  const double theta = slope_deg * std::numbers::pi / 180;
  const Eigen::Vector3d n(std::sin(theta), 0, std::cos(theta));  // the plane falls along +x
  const Eigen::Vector3d d(std::cos(theta), 0, -std::sin(theta));
  const Eigen::Vector3d axis = n.cross(d);
  RockState s;
  // The principal frame's third axis (largest moment) along the spin axis.
  s.orientation = Eigen::AngleAxisd(angle_rad, axis) *
                  Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis);
  s.velocity_m_s = Eigen::Vector3d(std::hypot(impact.vx, impact.vy), 0, impact.vz);
  s.angular_velocity_rad_s = s.orientation.conjugate() * (impact.omega * axis);
  TerrainSample ground;
  scene.terrain.Sample(20, 0, &ground);
  double lowest = 1e9;
  for (const Eigen::Vector3d& b : scene.rock.vertices_m)
    lowest = std::min(lowest, n.dot(s.orientation * b));
  s.position_m = Eigen::Vector3d(20, 0, ground.height_m) + (0.001 - lowest) * n;
  return s;
}

}  // namespace talus::scenes
