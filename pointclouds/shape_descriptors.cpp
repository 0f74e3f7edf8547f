#include "pointclouds/shape_descriptors.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <queue>
#include <vector>

namespace talus::pointclouds {
namespace {

// Non-unit outward normal of triangle t, twice its area long.
Eigen::Vector3d FaceNormal(const Polyhedron& poly, std::size_t t) {
  const auto& tri = poly.triangles[t];
  const Eigen::Vector3d& a = poly.vertices_m[tri[0]];
  return (poly.vertices_m[tri[1]] - a).cross(poly.vertices_m[tri[2]] - a);
}

// Width of the convex polyhedron along each face normal (infinity for degenerate triangles):
// the distance from the face's plane to the vertex lowest along its normal. The lowest vertex is
// found by walking downhill over the vertex graph (for a convex polyhedron the only local
// minimum of a linear function), starting from that of a neighbouring face, visited in
// breadth-first order; so the cost stays near linear in the number of faces.
std::vector<double> WidthsAlongFaceNormals(const Polyhedron& poly) {
  const std::size_t nv = poly.vertices_m.size(), nf = poly.triangles.size();
  std::vector<std::vector<int>> neighbours(nv), faces_of(nv);
  for (std::size_t t = 0; t < nf; ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = poly.triangles[t][k], b = poly.triangles[t][(k + 1) % 3];
      neighbours[a].push_back(b);
      neighbours[b].push_back(a);
      faces_of[a].push_back(static_cast<int>(t));
    }
  std::vector<double> widths(nf, std::numeric_limits<double>::infinity());
  std::vector<int> start(nf, -1);
  std::vector<char> seen(nf, 0);
  for (std::size_t root = 0; root < nf; ++root) {
    if (seen[root]) continue;
    std::queue<std::size_t> queue;
    queue.push(root);
    seen[root] = 1;
    start[root] = poly.triangles[root][0];
    while (!queue.empty()) {
      const std::size_t t = queue.front();
      queue.pop();
      const Eigen::Vector3d n = FaceNormal(poly, t);
      int lowest = start[t];
      if (n.norm() > 0) {
        const Eigen::Vector3d u = n.normalized();
        for (bool moved = true; moved;) {
          moved = false;
          for (int w : neighbours[lowest])
            if (u.dot(poly.vertices_m[w]) < u.dot(poly.vertices_m[lowest])) {
              lowest = w;
              moved = true;
            }
        }
        widths[t] = u.dot(poly.vertices_m[poly.triangles[t][0]] - poly.vertices_m[lowest]);
      }
      for (int k = 0; k < 3; ++k)
        for (int f : faces_of[poly.triangles[t][k]])
          if (!seen[f]) {
            seen[f] = 1;
            start[f] = lowest;
            queue.push(static_cast<std::size_t>(f));
          }
    }
  }
  return widths;
}

// Convex hull of points in the plane (Andrew's monotone chain), counter-clockwise.
std::vector<Eigen::Vector2d> Hull2d(std::vector<Eigen::Vector2d> p) {
  std::sort(p.begin(), p.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (p.size() < 3) return p;
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> h(2 * p.size());
  std::size_t k = 0;
  for (const Eigen::Vector2d& point : p) {
    while (k >= 2 && cross(h[k - 2], h[k - 1], point) <= 0) --k;
    h[k++] = point;
  }
  for (std::size_t i = p.size() - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(h[k - 2], h[k - 1], p[i]) <= 0) --k;
    h[k++] = p[i];
  }
  h.resize(k - 1);
  return h;
}

// Smallest-area rectangle around a convex polygon (one side lies along a polygon edge):
// its two sides, longer first.
Eigen::Vector2d MinAreaRectangle(const std::vector<Eigen::Vector2d>& h) {
  Eigen::Vector2d best(0, 0);
  double best_area = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < h.size(); ++i) {
    const Eigen::Vector2d edge = h[(i + 1) % h.size()] - h[i];
    if (!(edge.norm() > 0)) continue;
    const Eigen::Vector2d d = edge.normalized(), q(-d.y(), d.x());
    double lo_d = std::numeric_limits<double>::infinity(), hi_d = -lo_d, lo_q = lo_d, hi_q = -lo_d;
    for (const auto& p : h) {
      lo_d = std::min(lo_d, p.dot(d));
      hi_d = std::max(hi_d, p.dot(d));
      lo_q = std::min(lo_q, p.dot(q));
      hi_q = std::max(hi_q, p.dot(q));
    }
    const double w = hi_d - lo_d, l = hi_q - lo_q;
    if (w * l < best_area) {
      best_area = w * l;
      best = Eigen::Vector2d(std::max(w, l), std::min(w, l));
    }
  }
  return best;
}

}  // namespace

const char* ShapeClassName(ShapeClass shape_class) {
  switch (shape_class) {
    case ShapeClass::kEquant:
      return "equant";
    case ShapeClass::kPlaty:
      return "platy";
    case ShapeClass::kElongated:
      return "elongated";
    case ShapeClass::kBladed:
      return "bladed";
  }
  return "unknown";
}

ShapeClass ClassifyZingg(double b_over_a, double c_over_b) {
  if (b_over_a > kZinggRatio)
    return c_over_b > kZinggRatio ? ShapeClass::kEquant : ShapeClass::kPlaty;
  return c_over_b > kZinggRatio ? ShapeClass::kElongated : ShapeClass::kBladed;
}

ShapeDescriptors DescribeShape(const Polyhedron& hull) {
  ShapeDescriptors s;
  const std::vector<Eigen::Vector3d> v = UsedVertices(hull);
  if (v.size() < 4) return s;

  // Surface area, and the smallest width over the face normals.
  const std::vector<double> widths = WidthsAlongFaceNormals(hull);
  double c = std::numeric_limits<double>::infinity();
  Eigen::Vector3d thin = Eigen::Vector3d::UnitZ();
  for (std::size_t t = 0; t < hull.triangles.size(); ++t) {
    const Eigen::Vector3d n = FaceNormal(hull, t);
    s.surface_area_m2 += 0.5 * n.norm();
    if (widths[t] < c) {
      c = widths[t];
      thin = n.normalized();
    }
  }

  // The outline seen along the thinnest direction, and its smallest bounding rectangle.
  const Eigen::Vector3d e1 = thin.unitOrthogonal(), e2 = thin.cross(e1);
  std::vector<Eigen::Vector2d> outline;
  outline.reserve(v.size());
  for (const auto& p : v) outline.emplace_back(p.dot(e1), p.dot(e2));
  const Eigen::Vector2d ab = MinAreaRectangle(Hull2d(std::move(outline)));
  std::array<double, 3> dims = {ab.x(), ab.y(), c};
  std::sort(dims.begin(), dims.end(), std::greater<>());
  s.dimensions_m = Eigen::Vector3d(dims[0], dims[1], dims[2]);
  s.b_over_a = dims[1] / dims[0];
  s.c_over_b = dims[2] / dims[1];
  s.shape_class = ClassifyZingg(s.b_over_a, s.c_over_b);

  const double volume = ComputeMassProperties(hull, 1.0).volume_m3;
  s.sphericity = std::cbrt(std::numbers::pi) * std::pow(6 * volume, 2.0 / 3.0) / s.surface_area_m2;
  return s;
}

}  // namespace talus::pointclouds
