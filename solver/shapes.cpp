#include "solver/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

namespace talus {
namespace {

// Appends the convex planar face through the given vertices, triangulated as a fan in
// counter-clockwise order about the outward normal.
void AddConvexFace(Polyhedron& poly, std::vector<int> ids, const Eigen::Vector3d& outward) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (int id : ids) centre += poly.vertices_m[id];
  centre /= static_cast<double>(ids.size());
  const Eigen::Vector3d u = (poly.vertices_m[ids[0]] - centre).normalized();
  const Eigen::Vector3d w = outward.normalized().cross(u);
  auto angle = [&](int id) {
    const Eigen::Vector3d d = poly.vertices_m[id] - centre;
    return std::atan2(d.dot(w), d.dot(u));
  };
  std::sort(ids.begin(), ids.end(), [&](int p, int q) { return angle(p) < angle(q); });
  for (std::size_t k = 1; k + 1 < ids.size(); ++k)
    poly.triangles.push_back({ids[0], ids[k], ids[k + 1]});
}

}  // namespace

Polyhedron MakeBox(double a_m, double b_m, double c_m) {
  return MakeBevelledBox(a_m, b_m, c_m, 0.0);
}

Polyhedron MakeOctahedron(double a_m, double b_m, double c_m) {
  Polyhedron poly;
  const double h[3] = {a_m / 2, b_m / 2, c_m / 2};
  for (int axis = 0; axis < 3; ++axis)
    for (int s : {1, -1}) {
      Eigen::Vector3d v = Eigen::Vector3d::Zero();
      v[axis] = s * h[axis];
      poly.vertices_m.push_back(v);  // index 2 * axis + (s < 0)
    }
  for (int sx : {0, 1})
    for (int sy : {0, 1})
      for (int sz : {0, 1}) {
        const Eigen::Vector3d outward(sx ? -1 : 1, sy ? -1 : 1, sz ? -1 : 1);
        AddConvexFace(poly, {sx, 2 + sy, 4 + sz}, outward);
      }
  return poly;
}

Polyhedron MakeIcosphere(double radius_m, int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& p : v) p.normalize();
  for (int level = 0; level < subdivisions; ++level) {
    std::map<std::pair<int, int>, int> midpoint;
    auto mid = [&](int a, int b) {
      const std::pair<int, int> key(std::min(a, b), std::max(a, b));
      auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      const int id = static_cast<int>(v.size()) - 1;
      midpoint.emplace(key, id);
      return id;
    };
    std::vector<std::array<int, 3>> refined;
    refined.reserve(f.size() * 4);
    for (const auto& tri : f) {
      const int ab = mid(tri[0], tri[1]), bc = mid(tri[1], tri[2]), ca = mid(tri[2], tri[0]);
      refined.push_back({tri[0], ab, ca});
      refined.push_back({tri[1], bc, ab});
      refined.push_back({tri[2], ca, bc});
      refined.push_back({ab, bc, ca});
    }
    f = std::move(refined);
  }
  Polyhedron poly;
  for (const auto& p : v) poly.vertices_m.push_back(radius_m * p);
  poly.triangles = std::move(f);
  return poly;
}

Polyhedron MakeEllipsoid(double a_m, double b_m, double c_m, int subdivisions) {
  Polyhedron poly = MakeIcosphere(1.0, subdivisions);
  for (auto& p : poly.vertices_m)
    p = Eigen::Vector3d(p.x() * a_m / 2, p.y() * b_m / 2, p.z() * c_m / 2);
  return poly;
}

Polyhedron MakeCylinder(double radius_m, double height_m, int segments) {
  Polyhedron poly;
  std::vector<int> top, bottom;
  for (int k = 0; k < segments; ++k) {
    const double phi = 2.0 * std::numbers::pi * k / segments;
    const double x = radius_m * std::cos(phi), y = radius_m * std::sin(phi);
    poly.vertices_m.emplace_back(x, y, height_m / 2);
    poly.vertices_m.emplace_back(x, y, -height_m / 2);
    top.push_back(2 * k);
    bottom.push_back(2 * k + 1);
  }
  AddConvexFace(poly, top, Eigen::Vector3d::UnitZ());
  AddConvexFace(poly, bottom, -Eigen::Vector3d::UnitZ());
  for (int k = 0; k < segments; ++k) {
    const int n = (k + 1) % segments;
    const double phi = 2.0 * std::numbers::pi * (k + 0.5) / segments;
    AddConvexFace(poly, {2 * k, 2 * k + 1, 2 * n, 2 * n + 1},
                  Eigen::Vector3d(std::cos(phi), std::sin(phi), 0));
  }
  return poly;
}

Polyhedron MakeBevelledBox(double a_m, double b_m, double c_m, double bevel_m) {
  const Eigen::Vector3d h(a_m / 2, b_m / 2, c_m / 2);
  Polyhedron poly;
  // Vertex of corner (sx, sy, sz) lying on the face normal to `axis`: full extent along the axis,
  // inset by the bevel along the other two. Without a bevel the three coincide: one vertex.
  auto id = [&](int corner, int axis) { return bevel_m > 0 ? 3 * corner + axis : corner; };
  auto sign = [](int corner, int axis) { return (corner >> axis) & 1 ? -1.0 : 1.0; };
  for (int corner = 0; corner < 8; ++corner)
    for (int axis = 0; axis < (bevel_m > 0 ? 3 : 1); ++axis) {
      Eigen::Vector3d v;
      for (int k = 0; k < 3; ++k) v[k] = sign(corner, k) * (k == axis ? h[k] : h[k] - bevel_m);
      poly.vertices_m.push_back(v);
    }
  // Main faces: the four corners on the side s of each axis.
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      std::vector<int> ids;
      for (int corner = 0; corner < 8; ++corner)
        if (((corner >> axis) & 1) == side) ids.push_back(id(corner, axis));
      Eigen::Vector3d outward = Eigen::Vector3d::Zero();
      outward[axis] = side ? -1 : 1;
      AddConvexFace(poly, ids, outward);
    }
  if (bevel_m <= 0) return poly;
  // Edge bevels: for the edge along `free` between faces `p` and `q`.
  for (int free = 0; free < 3; ++free) {
    const int p = (free + 1) % 3, q = (free + 2) % 3;
    for (int sp = 0; sp < 2; ++sp)
      for (int sq = 0; sq < 2; ++sq) {
        std::vector<int> ids;
        for (int corner = 0; corner < 8; ++corner)
          if (((corner >> p) & 1) == sp && ((corner >> q) & 1) == sq) {
            ids.push_back(id(corner, p));
            ids.push_back(id(corner, q));
          }
        Eigen::Vector3d outward = Eigen::Vector3d::Zero();
        outward[p] = sp ? -1 : 1;
        outward[q] = sq ? -1 : 1;
        AddConvexFace(poly, ids, outward);
      }
  }
  // Corner triangles.
  for (int corner = 0; corner < 8; ++corner)
    AddConvexFace(poly, {id(corner, 0), id(corner, 1), id(corner, 2)},
                  Eigen::Vector3d(sign(corner, 0), sign(corner, 1), sign(corner, 2)));
  return poly;
}

double BevelForVolume(double a_m, double b_m, double c_m, double volume_m3) {
  auto volume = [&](double d) {
    return ComputeMassProperties(MakeBevelledBox(a_m, b_m, c_m, d), 1.0).volume_m3;
  };
  double lo = 0, hi = 0.5 * std::min({a_m, b_m, c_m}) * (1 - 1e-9);
  if (volume_m3 > volume(lo) * (1 + 1e-12) || volume_m3 < volume(hi)) return -1;
  for (int k = 0; k < 100; ++k) {
    const double mid = 0.5 * (lo + hi);
    (volume(mid) > volume_m3 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace talus
