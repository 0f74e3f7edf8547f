#include "pointclouds/hull_simplify.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cassert>
#include <cstdio>
#include <limits>
#include <vector>

#include "pointclouds/convex_hull.hpp"

namespace talus::pointclouds {
namespace {

struct Plane {
  Eigen::Vector3d normal;  // unit, outward
  double offset_m;         // normal . x on the plane
};

std::vector<Plane> FacePlanes(const Polyhedron& poly) {
  std::vector<Plane> planes;
  planes.reserve(poly.triangles.size());
  for (const auto& t : poly.triangles) {
    const Eigen::Vector3d& a = poly.vertices_m[t[0]];
    const Eigen::Vector3d n = (poly.vertices_m[t[1]] - a).cross(poly.vertices_m[t[2]] - a);
    if (!(n.norm() > 0)) continue;
    planes.push_back({n.normalized(), n.normalized().dot(a)});
  }
  return planes;
}

// Distance of a point outside the convex polyhedron to the farthest of its face planes
// (negative inside).
double OutsideDistance(const std::vector<Plane>& planes, const Eigen::Vector3d& p) {
  double d = -std::numeric_limits<double>::infinity();
  for (const auto& plane : planes) d = std::max(d, plane.normal.dot(p) - plane.offset_m);
  return d;
}

Eigen::Vector3d PrincipalMoments(const Polyhedron& poly) {
  const MassProperties mp = ComputeMassProperties(poly, 1.0);
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(mp.inertia_kg_m2, Eigen::EigenvaluesOnly)
      .eigenvalues();
}

}  // namespace

Polyhedron SimplifyHull(const Polyhedron& hull, int max_vertices, SimplifyReport* report) {
  assert(max_vertices >= 4);
  // Candidates: the vertices that the triangles use.
  const std::vector<Eigen::Vector3d> candidates = UsedVertices(hull);

  Polyhedron result = hull;
  std::vector<char> chosen(candidates.size(), 1);
  if (static_cast<int>(candidates.size()) > max_vertices) {
    // Greedy insertion: start from a spanning tetrahedron, add the farthest vertex outside.
    const std::string source = "hull simplification";
    std::fill(chosen.begin(), chosen.end(), 0);
    std::vector<Eigen::Vector3d> selected;
    for (std::size_t i : SpanningTetrahedron(candidates, source)) {
      chosen[i] = 1;
      selected.push_back(candidates[i]);
    }
    result = ComputeConvexHull(selected, source);
    while (static_cast<int>(selected.size()) < max_vertices) {
      const std::vector<Plane> planes = FacePlanes(result);
      double farthest = 0;
      std::size_t arg = candidates.size();
      for (std::size_t i = 0; i < candidates.size(); ++i) {
        if (chosen[i]) continue;
        const double d = OutsideDistance(planes, candidates[i]);
        if (d > farthest) {
          farthest = d;
          arg = i;
        }
      }
      if (arg == candidates.size()) break;  // every vertex left is inside already
      chosen[arg] = 1;
      selected.push_back(candidates[arg]);
      result = ComputeConvexHull(selected, source);
    }
  }

  if (report) {
    SimplifyReport& r = *report;
    r = SimplifyReport{};
    r.vertices_before = static_cast<int>(candidates.size());
    r.vertices_after = static_cast<int>(result.vertices_m.size());
    r.volume_before_m3 = ComputeMassProperties(hull, 1.0).volume_m3;
    r.volume_after_m3 = ComputeMassProperties(result, 1.0).volume_m3;
    r.volume_error = (r.volume_before_m3 - r.volume_after_m3) / r.volume_before_m3;
    const Eigen::Vector3d before = PrincipalMoments(hull), after = PrincipalMoments(result);
    r.inertia_error = ((after - before).array().abs() / before.array()).maxCoeff();
    const std::vector<Plane> planes = FacePlanes(result);
    for (std::size_t i = 0; i < candidates.size(); ++i)
      if (!chosen[i])
        r.max_distance_m = std::max(r.max_distance_m, OutsideDistance(planes, candidates[i]));
  }
  return result;
}

std::string SimplifyReport::BriefReport() const {
  char line[200];
  std::snprintf(line, sizeof line,
                "%d -> %d hull vertices: volume -%.2f %%, principal moments within %.2f %%, "
                "largest deviation %.3g m",
                vertices_before, vertices_after, 100 * volume_error, 100 * inertia_error,
                max_distance_m);
  return line;
}

}  // namespace talus::pointclouds
