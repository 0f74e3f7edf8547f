#pragma once
// Built-in rock shapes by name and dimensions, as closed polyhedra (built by solver/shapes.hpp).

#include <optional>
#include <string>
#include <vector>

#include "solver/polyhedron.hpp"

namespace talus::pointclouds {

// A built-in shape, centred at the origin with its a, b, c along x, y, z.
struct BuiltinSpec {
  std::string name;  // box, ellipsoid, icosphere, cylinder (or disk), eota111, eota221
  // box: a, b, c (one value: a cube); ellipsoid: diameters a, b, c (one value: a sphere);
  // icosphere: diameter (none: 1 m); cylinder, disk: diameter, height (axis along z);
  // eota111, eota221: bounding box a, b, c, or the long side a with the standard proportions
  // (1:1:1, 2:2:1), or none: the standard block of 1 m^3 (or of volume_m3).
  std::vector<double> dimensions_m;
  int subdivisions = 2;  // ellipsoid, icosphere: 10 * 4^subdivisions + 2 vertices
  int segments = 24;     // cylinder, disk: vertices on each end circle
  // EOTA blocks: the volume the bevel is chosen for. Without it, blocks of given dimensions keep
  // the standard ratio of bevel to shortest side (that of the 1 m^3 block).
  std::optional<double> volume_m3;

  // False, with the field, value and reason in *why, for an unknown name or bad dimensions.
  bool IsValid(std::string* why) const;
};

// The names MakeBuiltinShape accepts.
const std::vector<std::string>& BuiltinShapeNames();

// Builds the shape; *description (if given) says what was built, e.g.
// "eota221 0.93 x 0.93 x 0.47 m, bevel 0.103 m". Throws InputError for an invalid spec or an
// EOTA volume that no bevel of the given box reaches.
Polyhedron MakeBuiltinShape(const BuiltinSpec& spec, std::string* description = nullptr);

}  // namespace talus::pointclouds
