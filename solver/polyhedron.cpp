#include "solver/polyhedron.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace talus {
namespace {

// The hull's edges as RockShape::neighbours, from its triangles: each edge once per end.
void SetNeighbours(RockShape& rock) {
  std::vector<std::vector<int>> lists(rock.vertices_m.size());
  for (const auto& t : rock.triangles)
    for (int e = 0; e < 3; ++e) {
      lists[t[e]].push_back(t[(e + 1) % 3]);
      lists[t[(e + 1) % 3]].push_back(t[e]);
    }
  rock.neighbour_start.assign(1, 0);
  for (std::vector<int>& list : lists) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    rock.neighbours.insert(rock.neighbours.end(), list.begin(), list.end());
    rock.neighbour_start.push_back(static_cast<int>(rock.neighbours.size()));
  }
}

}  // namespace

std::vector<Eigen::Vector3d> UsedVertices(const Polyhedron& poly) {
  std::vector<char> used(poly.vertices_m.size(), 0);
  for (const auto& t : poly.triangles)
    for (int k : t) used[k] = 1;
  std::vector<Eigen::Vector3d> vertices;
  for (std::size_t i = 0; i < used.size(); ++i)
    if (used[i]) vertices.push_back(poly.vertices_m[i]);
  return vertices;
}

MassProperties ComputeMassProperties(const Polyhedron& poly, double density_kg_m3) {
  // Coordinates are taken relative to the vertex mean so that large (georeferenced) offsets
  // cost no precision. Each triangle (a, b, c) and that origin span a signed tetrahedron of volume
  // a.(b x c)/6 with centroid (a + b + c)/4 and second-moment tensor (V/20)(a a' + b b' + c c' + s
  // s'), s = a + b + c.
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  for (const auto& v : poly.vertices_m) origin += v;
  if (!poly.vertices_m.empty()) origin /= static_cast<double>(poly.vertices_m.size());
  double volume = 0;
  Eigen::Vector3d first = Eigen::Vector3d::Zero();
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  for (const auto& t : poly.triangles) {
    const Eigen::Vector3d a = poly.vertices_m[t[0]] - origin;
    const Eigen::Vector3d b = poly.vertices_m[t[1]] - origin;
    const Eigen::Vector3d c = poly.vertices_m[t[2]] - origin;
    const double v = a.dot(b.cross(c)) / 6.0;
    const Eigen::Vector3d s = a + b + c;
    volume += v;
    first += v * s / 4.0;
    second += (v / 20.0) *
              (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  MassProperties mp;
  mp.volume_m3 = volume;
  if (volume == 0) return mp;
  const Eigen::Vector3d centroid = first / volume;
  mp.centroid_m = origin + centroid;
  // Second moment about the centroid, then inertia = trace(C) I - C, scaled by density.
  const Eigen::Matrix3d c = second - volume * centroid * centroid.transpose();
  mp.inertia_kg_m2 = density_kg_m3 * (c.trace() * Eigen::Matrix3d::Identity() - c);
  return mp;
}

RockShape MakeRockShape(const Polyhedron& hull, double density_kg_m3) {
  const MassProperties mp = ComputeMassProperties(hull, density_kg_m3);
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(mp.inertia_kg_m2);
  Eigen::Matrix3d axes = eig.eigenvectors();  // columns: principal axes, ascending moments
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);

  RockShape rock;
  rock.mass_kg = density_kg_m3 * mp.volume_m3;
  rock.volume_m3 = mp.volume_m3;
  rock.inertia_kg_m2 = eig.eigenvalues();
  rock.principal_to_input = Eigen::Quaterniond(axes).normalized();
  rock.centroid_input_m = mp.centroid_m;

  // The used vertices in index order (as UsedVertices), and the faces renumbered to match.
  std::vector<int> renumber(hull.vertices_m.size(), -1);
  for (const auto& t : hull.triangles)
    for (int k : t) renumber[k] = 0;
  for (std::size_t i = 0; i < renumber.size(); ++i) {
    if (renumber[i] < 0) continue;
    renumber[i] = static_cast<int>(rock.vertices_m.size());
    const Eigen::Vector3d local = axes.transpose() * (hull.vertices_m[i] - mp.centroid_m);
    rock.vertices_m.push_back(local);
    rock.bounding_radius_m = std::max(rock.bounding_radius_m, local.norm());
  }
  for (const auto& t : hull.triangles)
    rock.triangles.push_back({renumber[t[0]], renumber[t[1]], renumber[t[2]]});
  SetNeighbours(rock);
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& b : rock.vertices_m) {
    lo = lo.cwiseMin(b);
    hi = hi.cwiseMax(b);
  }
  rock.thickness_m = (hi - lo).minCoeff();
  rock.length_m = (hi - lo).maxCoeff();
  return rock;
}

bool RockShape::IsValid(std::string* why) const {
  std::ostringstream msg;
  if (vertices_m.size() < 4)
    msg << "rock has " << vertices_m.size() << " vertices; a solid needs at least 4";
  else if (!(mass_kg > 0) || !std::isfinite(mass_kg))
    msg << "rock mass " << mass_kg << " kg must be positive and finite";
  else if (!(inertia_kg_m2.minCoeff() > 0) || !inertia_kg_m2.allFinite())
    msg << "principal moments (" << inertia_kg_m2.transpose() << ") kg m^2 must be positive";
  else if (inertia_kg_m2(0) + inertia_kg_m2(1) < inertia_kg_m2(2) * (1 - 1e-9))
    msg << "principal moments (" << inertia_kg_m2.transpose()
        << ") kg m^2 violate the triangle inequality";
  else if (!(bounding_radius_m > 0) || !std::isfinite(bounding_radius_m))
    msg << "rock bounding radius " << bounding_radius_m << " m must be positive";
  else if (!(thickness_m > 0) || !(thickness_m <= 2 * bounding_radius_m))
    msg << "rock thickness " << thickness_m << " m must be in (0, 2 bounding radius]";
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

RockShape ScaleRockShape(const RockShape& rock, double factor) {
  RockShape out = rock;
  for (Eigen::Vector3d& v : out.vertices_m) v *= factor;
  const double cube = factor * factor * factor;
  out.volume_m3 *= cube;
  out.mass_kg *= cube;
  out.inertia_kg_m2 *= cube * factor * factor;
  out.bounding_radius_m *= factor;
  out.thickness_m *= factor;
  out.length_m *= factor;
  out.centroid_input_m *= factor;
  return out;
}

}  // namespace talus
