#include "scenes/scenes.hpp"

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
