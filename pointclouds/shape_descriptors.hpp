#pragma once
// Shape descriptors of a rock hull: principal dimensions, Zingg class and sphericity.

#include <Eigen/Core>
#include <string>

#include "solver/polyhedron.hpp"

namespace talus::pointclouds {

// Zingg (1935) classes from the axis ratios b/a and c/b, each against 2/3:
//   b/a > 2/3, c/b > 2/3: equant;     b/a > 2/3, c/b <= 2/3: platy (disc);
//   b/a <= 2/3, c/b > 2/3: elongated;  b/a <= 2/3, c/b <= 2/3: bladed.
enum class ShapeClass { kEquant, kPlaty, kElongated, kBladed };
inline constexpr double kZinggRatio = 2.0 / 3.0;
const char* ShapeClassName(ShapeClass shape_class);  // "equant", "platy", "elongated", "bladed"
ShapeClass ClassifyZingg(double b_over_a, double c_over_b);

struct ShapeDescriptors {
  // Sides of a tight bounding box, a >= b >= c: c is the smallest width of the hull over its
  // face normals, a and b the sides of the smallest-area rectangle around its outline seen along
  // that direction. Exact for boxes, bevelled boxes, prisms and ellipsoids; unlike extents along
  // the principal axes, it does not depend on how equal moments pick their axes.
  Eigen::Vector3d dimensions_m = Eigen::Vector3d::Zero();
  double b_over_a = 0;
  double c_over_b = 0;
  ShapeClass shape_class = ShapeClass::kEquant;
  double surface_area_m2 = 0;
  // Wadell's true sphericity: surface of the sphere of equal volume over the hull's surface,
  // pi^(1/3) (6 V)^(2/3) / A, in (0, 1]; 1 for a sphere, 0.806 for a cube.
  double sphericity = 0;
};

// Descriptors of a closed convex polyhedron (they do not depend on its position or orientation).
ShapeDescriptors DescribeShape(const Polyhedron& hull);

}  // namespace talus::pointclouds
