#pragma once
// Built-in rock shapes as closed polyhedra centred at the origin, dimensions along x, y, z.

#include "solver/polyhedron.hpp"

namespace talus {

Polyhedron MakeBox(double a_m, double b_m, double c_m);
// Octahedron with vertex-to-vertex extents a, b, c along x, y, z.
Polyhedron MakeOctahedron(double a_m, double b_m, double c_m);
// Subdivided icosahedron with vertices on the sphere: 10 * 4^subdivisions + 2 vertices.
Polyhedron MakeIcosphere(double radius_m, int subdivisions);
// Icosphere scaled to extents a, b, c along x, y, z.
Polyhedron MakeEllipsoid(double a_m, double b_m, double c_m, int subdivisions);
// Prism over a regular polygon of `segments` vertices on the circle of radius_m; axis along z.
Polyhedron MakeCylinder(double radius_m, double height_m, int segments);
// Box a x b x c with all twelve edges bevelled by bevel_m on each adjacent face (24 vertices),
// the EOTA test block of the rockfall-barrier standard; bevel_m < min(a, b, c) / 2.
Polyhedron MakeBevelledBox(double a_m, double b_m, double c_m, double bevel_m);
// The bevel that gives a bevelled box of the requested volume (bisection on the exact volume);
// negative when the volume is not reachable (more than the box, or less than the deepest bevel).
double BevelForVolume(double a_m, double b_m, double c_m, double volume_m3);

}  // namespace talus
