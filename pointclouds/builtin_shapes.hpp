#pragma once
// Built-in rock shapes by name and dimensions, as closed polyhedra (built by solver/shapes.hpp).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "solver/polyhedron.hpp"

namespace talus::pointclouds {

// A built-in shape, centred at the origin with its a, b, c along x, y, z.
struct BuiltinSpec {
  std::string name;  // box, ellipsoid, icosphere, cylinder (or disk), rock, eota111, eota221
  // box: a, b, c (one value: a cube); ellipsoid, rock: diameters a, b, c (one value: a sphere);
  // icosphere: diameter (none: 1 m); cylinder, disk: diameter, height (axis along z);
  // eota111, eota221: bounding box a, b, c, or the long side a with the standard proportions
  // (1:1:1, 2:2:1), or none: the standard block of 1 m^3 (or of volume_m3).
  std::vector<double> dimensions_m;
  int subdivisions = 2;  // ellipsoid, icosphere: 10 * 4^subdivisions + 2 vertices
  int segments = 24;     // cylinder, disk: vertices on each end circle
  // rock: the convex hull of `points` random points (4 .. 10^6) on the ellipsoid a x b x c, each
  // at the radius factor 1 + roughness * w, w uniform in [-1, 1] (0 <= roughness <= 0.5). The
  // points are drawn from RockRandom(shape_seed, kRockShapeStream): the same seed gives the same
  // points, bit for bit, on every platform, and so the same rock. See MakeBuiltinShape for the
  // convention on size.
  int points = 32;
  double roughness = 0.15;
  std::uint64_t shape_seed = 0;
  // EOTA blocks: the volume the bevel is chosen for. Without it, blocks of given dimensions keep
  // the standard ratio of bevel to shortest side (that of the 1 m^3 block).
  std::optional<double> volume_m3;

  // False, with the field, value and reason in *why, for an unknown name or bad dimensions.
  bool IsValid(std::string* why) const;
};

// The stream index of RockRandom (solver/random.hpp) that rock shapes are drawn from; apart from
// rock indices, so that a shape seed equal to a release seed draws other numbers than any rock.
inline constexpr std::uint64_t kRockShapeStream = 0x524f434b53484150;  // "ROCKSHAP"

// The names MakeBuiltinShape accepts.
const std::vector<std::string>& BuiltinShapeNames();

// Builds the shape; *description (if given) says what was built, e.g.
// "eota221 0.93 x 0.93 x 0.47 m, bevel 0.103 m". Throws InputError for an invalid spec or an
// EOTA volume that no bevel of the given box reaches.
//
// rock: directions uniform on the unit sphere (rejection from the cube, so only +, *, / and sqrt,
// which IEEE 754 rounds the same everywhere; no fused multiply-adds), stretched to the ellipsoid
// and perturbed radially; the hull of those points (pointclouds/convex_hull.hpp, so at most
// `points` vertices) is then rescaled along x, y and z so that its bounding box is exactly
// a x b x c, centred at the origin: "a rock of 0.46 x 0.30 x 0.20 m" has those extents. A draw
// whose rescaled hull holds less than 1 % of the ellipsoid's volume (pi/6 abc; few points, nearly
// coplanar) is discarded and the next points of the same stream are drawn, so that every seed
// gives a solid rock.
Polyhedron MakeBuiltinShape(const BuiltinSpec& spec, std::string* description = nullptr);

}  // namespace talus::pointclouds
