#pragma once
// Convex hulls of point sets, computed by PCL (qhull underneath).

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "solver/polyhedron.hpp"

namespace talus::pointclouds {

// Relative flatness below which points count as coplanar (or collinear): the largest distance
// from the best plane (or line) found, over the extent of the points. Leaves room for the
// single-precision arithmetic inside PCL.
inline constexpr double kDegenerateTolerance = 1e-6;

// Largest coordinate magnitude accepted (m): far beyond any georeferenced coordinate (UTM
// northings are below 10^7 m), small enough that squared distances stay finite. Larger values
// are not metres (or not numbers the file meant).
inline constexpr double kMaxCoordinate_m = 1e9;

// Four points that span a solid: the point farthest from the mean, the point farthest from it,
// the point farthest from their line and the point farthest from the plane of the three.
// Throws InputError, naming `source`, for fewer than 4 points, a coordinate that is not finite
// or beyond kMaxCoordinate_m, or points that all coincide, are collinear or coplanar (within
// kDegenerateTolerance of their extent).
std::array<std::size_t, 4> SpanningTetrahedron(const std::vector<Eigen::Vector3d>& points_m,
                                               const std::string& source);

// Convex hull of the points: a closed triangle mesh with counter-clockwise triangles seen from
// outside, whose vertices are the input points on the hull, copied in double precision (PCL
// only decides which points and triangles, in single precision, relative to the points' centre).
// Throws InputError as SpanningTetrahedron does.
Polyhedron ComputeConvexHull(const std::vector<Eigen::Vector3d>& points_m,
                             const std::string& source);

}  // namespace talus::pointclouds
