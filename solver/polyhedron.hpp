#pragma once
// Closed triangulated polyhedra, their exact mass properties, and the rock shape the solver uses.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <string>
#include <vector>

namespace talus {

// A closed, consistently oriented triangle mesh (counter-clockwise seen from outside).
struct Polyhedron {
  std::vector<Eigen::Vector3d> vertices_m;
  std::vector<std::array<int, 3>> triangles;
};

// The vertices that at least one triangle uses, in index order.
std::vector<Eigen::Vector3d> UsedVertices(const Polyhedron& poly);

// Mass properties of a homogeneous solid polyhedron, by exact integration over the tetrahedra
// that its triangles span with the origin (divergence theorem).
struct MassProperties {
  double volume_m3 = 0;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero();  // about the centroid, for density
};
MassProperties ComputeMassProperties(const Polyhedron& poly, double density_kg_m3);

// The rock as the solver sees it: a convex polyhedron in its principal frame.
struct RockShape {
  std::vector<Eigen::Vector3d>
      vertices_m;  // hull vertices, principal frame, origin at the centroid
  // Hull faces: indices into vertices_m, counter-clockwise seen from outside (the scarring soil
  // clips them by the terrain, solver/soil.hpp). Empty for a shape not made by MakeRockShape.
  std::vector<std::array<int, 3>> triangles;
  // The hull's edges, for walks over it (contact detection on hulls of many vertices): the
  // neighbours of vertex k are neighbours[neighbour_start[k] .. neighbour_start[k + 1]), in
  // ascending order. Empty with the triangles.
  std::vector<int> neighbour_start;
  std::vector<int> neighbours;
  double mass_kg = 0;
  double volume_m3 = 0;
  Eigen::Vector3d inertia_kg_m2 = Eigen::Vector3d::Ones();  // principal moments, ascending
  double bounding_radius_m = 0;                             // max |vertex|
  double thickness_m = 0;  // smallest extent of the vertices along the principal axes
  double length_m = 0;     // largest extent of the vertices along the principal axes
  // x_input = centroid_input_m + principal_to_input * x_principal: how the principal frame sits in
  // the frame the shape was given in (point cloud axes, or a built-in's a, b, c along x, y, z).
  Eigen::Quaterniond principal_to_input = Eigen::Quaterniond::Identity();
  Eigen::Vector3d centroid_input_m = Eigen::Vector3d::Zero();

  // The solver's orientation (principal frame -> world) of a shape placed with `shape_orientation`
  // (rotation of the shape as given, about its centre of mass), and back.
  Eigen::Quaterniond PrincipalOrientation(const Eigen::Quaterniond& shape_orientation) const {
    return (shape_orientation * principal_to_input).normalized();
  }
  Eigen::Quaterniond ShapeOrientation(const Eigen::Quaterniond& principal_orientation) const {
    return (principal_orientation * principal_to_input.conjugate()).normalized();
  }

  bool IsValid(std::string* why) const;
};

// Builds the solver's rock from a closed convex polyhedron: mass properties at the given density,
// a right-handed principal frame with ascending moments, vertices expressed in it.
// Hull vertices that are not used by any triangle are dropped.
RockShape MakeRockShape(const Polyhedron& hull, double density_kg_m3);

// The same rock scaled by `factor` (> 0) in every length about its centre of mass, at the same
// density: vertices and extents times factor, volume and mass times factor^3, principal moments
// times factor^5; the principal frame and how it sits in the input frame are unchanged.
RockShape ScaleRockShape(const RockShape& rock, double factor);

}  // namespace talus
