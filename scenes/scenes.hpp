#pragma once
// Scenes built in code, shared by the demo, the tests and the benchmarks.

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

}  // namespace talus::scenes
