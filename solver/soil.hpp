#pragma once
// The scarring soil of Lu et al. 2019 (docs/model.md, "The scarring soil"): the rock's part below
// the terrain and the velocity-squared scar drag on it.

#include <Eigen/Core>
#include <vector>

#include "solver/polyhedron.hpp"

namespace talus {

// The part of a rock's hull below a plane (the terrain's tangent plane), in world axes relative
// to the centre of mass.
struct SubmergedPart {
  double volume_m3 = 0;
  Eigen::Vector3d centroid_m = Eigen::Vector3d::Zero();  // relative to the centre of mass
  double depth_m = 0;  // of the deepest vertex below the plane, along its normal, >= 0
  // The part's points (relative to the centre of mass) least and most far along the direction
  // given to ClipBelowPlane: the rear and the front of the scar it cuts.
  Eigen::Vector3d rear_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d front_m = Eigen::Vector3d::Zero();
  // Vector areas (m^2) of the clipped hull faces (outward); the cut face closes them.
  std::vector<Eigen::Vector3d> face_areas;
  Eigen::Vector3d cut_area = Eigen::Vector3d::Zero();  // vector area of the cut face
  // Scratch space of ClipBelowPlane: the vertices relative to the plane point, their heights.
  std::vector<Eigen::Vector3d> scratch_points;
  std::vector<double> scratch_heights;

  bool empty() const { return !(volume_m3 > 0); }
  // Frontal area (m^2) seen along unit direction u: the area of the part's projection onto the
  // plane normal to u, the sum of u . a over the faces that face u (the part is convex).
  double FrontalArea(const Eigen::Vector3d& u) const;
};

// Clips the hull of `rock` (orientation `rotation`, principal frame -> world) by the half-space
// below the plane through `plane_point_m` (relative to the centre of mass) with upward unit normal
// `normal`: the hull's triangles cut by the plane, fan-triangulated, their tetrahedra with apex on
// the plane summed for volume and centroid (the cut face spans none); rear and front along
// `along` (any vector; zero: not computed). Reuses part's storage. Cost: one pass over the
// vertices and the triangles.
void ClipBelowPlane(const RockShape& rock, const Eigen::Matrix3d& rotation,
                    const Eigen::Vector3d& plane_point_m, const Eigen::Vector3d& normal,
                    SubmergedPart* part, const Eigen::Vector3d& along = Eigen::Vector3d::Zero());

}  // namespace talus
