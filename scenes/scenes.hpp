#pragma once
// Scenes built in code, shared by the demo, the tests and the benchmarks.

#include <array>
#include <cstdint>

#include "ensemble/release.hpp"
#include "solver/scene.hpp"
#include "solver/state.hpp"

namespace talus::scenes {

// The EOTA221 block of the Chant Sura experiments: 780 kg, 0.93 x 0.93 x 0.47 m, bevelled box of
// density 2500 kg/m^3 (the bevel is chosen so that the volume gives the mass).
RockShape Eota221();

// The benchmark ramp: 40 degree plane, 200 m horizontal slope, 150 m flat runout, 100 m wide,
// 2 m cells, ground "medium_hard" everywhere, default solver options, EOTA221 block.
Scene Ramp40();

// The release of the Ramp40 rocks: centre of mass 1 m above the ground at x = 10 m, y = 0, at
// rest, orientation of the shape uniform on SO(3) from (seed, rock) -- the release a scene file
// with that point gives (cases/ramp40), so the same-numbered rock starts the same everywhere.
ensemble::ReleaseSpec Ramp40ReleaseSpec(std::uint64_t seed, long rocks);

// Release state of rock `rock_index` of Ramp40ReleaseSpec.
RockState Ramp40Release(const Scene& ramp, std::uint64_t seed, std::uint64_t rock_index);

// A test incline: a plane falling along +x at slope_deg (0: flat), x in [0, length_m],
// y in [-length_m/2, length_m/2], with one ground category "test" of the given parameters.
Scene Incline(double slope_deg, const RockShape& rock, const GroundParams& ground,
              double length_m = 200, double cell_m = 5);

// The four single impacts of Lu et al. 2019 (Table 2: velocity, m/s, and rotation speed, rad/s,
// observed scar depth and length, m) with the soil fitted to each (Table 3: M_E, MN/m^2, C_s) and
// the paper's simulated scar depth and length (m); restated in lu2019_model.md.
struct Lu2019Impact {
  double vx, vy, vz, omega;
  double observed_depth_m, observed_length_m;
  double soil_strength_mn_m2, compaction_drag;
  double paper_depth_m, paper_length_m;
};
const std::array<Lu2019Impact, 4>& Lu2019Impacts();

// Impact `i` of Lu2019Impacts as the paper ran it, on a plane: the EOTA221 block on a plane of
// slope_deg (the impact points' slope is not published) falling along +x, the scarring soil of
// Table 3 under it with the paper's rebound plane (mu_min 0.55, mu_max 2, beta 185, kappa 3, no nu).
Scene Lu2019ImpactScene(int i, double slope_deg);
// The start of impact i: the measured velocity turned so that its horizontal part points down the
// plane, the block spinning at the measured rate about its major principal axis (largest moment)
// set along n x d (rolling forward), turned by `angle_rad` about that axis, its lowest vertex 1 mm
// above the plane at x = 20 m.
RockState Lu2019ImpactStart(const Scene& scene, int i, double slope_deg, double angle_rad);

}  // namespace talus::scenes
