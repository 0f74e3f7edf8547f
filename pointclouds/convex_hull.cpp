#include "pointclouds/convex_hull.hpp"

#include <pcl/console/print.h>
#include <pcl/point_types.h>
#include <pcl/surface/convex_hull.h>
// PCL's ConvexHull from its header implementation, on Qhull: Debian's libpcl_surface links VTK,
// which every talus call would then load at start-up.
#include <pcl/surface/impl/convex_hull.hpp>

#include <Eigen/Geometry>
#include <cstdint>
#include <mutex>
#include <queue>
#include <sstream>
#include <unordered_map>
#include <utility>

#include "common/error.hpp"

namespace talus::pointclouds {
namespace {

// PCL's verbosity is one global: silenced while any thread computes a hull (rocks get their own
// shapes in worker threads), and restored by the last one out, so that concurrent hulls cannot
// leave it silenced, or restore it while another still runs.
class QuietHullScope {
 public:
  QuietHullScope() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (depth_++ == 0) {
      previous_ = pcl::console::getVerbosityLevel();
      pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
    }
  }
  ~QuietHullScope() {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (--depth_ == 0) pcl::console::setVerbosityLevel(previous_);
  }
  QuietHullScope(const QuietHullScope&) = delete;
  QuietHullScope& operator=(const QuietHullScope&) = delete;

 private:
  static inline std::mutex mutex_;
  static inline int depth_ = 0;
  static inline pcl::console::VERBOSITY_LEVEL previous_ = pcl::console::L_INFO;
};

template <typename Distance>
std::size_t Farthest(const std::vector<Eigen::Vector3d>& points, Distance distance, double* best) {
  std::size_t arg = 0;
  *best = -1;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double d = distance(points[i]);
    if (d > *best) {
      *best = d;
      arg = i;
    }
  }
  return arg;
}

// Orients all triangles like their neighbours (a shared edge runs in opposite directions), then
// outward (positive volume). Throws when the mesh is not one closed surface.
void OrientOutward(Polyhedron& poly, const std::string& source) {
  const std::size_t n = poly.triangles.size();
  auto key = [](int a, int b) {
    return (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
           static_cast<std::uint32_t>(std::max(a, b));
  };
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> edges;
  for (std::size_t t = 0; t < n; ++t)
    for (int k = 0; k < 3; ++k)
      edges[key(poly.triangles[t][k], poly.triangles[t][(k + 1) % 3])].push_back(t);
  for (const auto& entry : edges)
    if (entry.second.size() != 2)
      throw InputError(source +
                       ": the convex hull is not a closed surface (nearly degenerate points?)");

  // Breadth-first over the triangles, flipping a neighbour that runs a shared edge the same way.
  auto has_directed = [&](std::size_t t, int a, int b) {
    const auto& tri = poly.triangles[t];
    for (int k = 0; k < 3; ++k)
      if (tri[k] == a && tri[(k + 1) % 3] == b) return true;
    return false;
  };
  std::vector<char> seen(n, 0);
  std::queue<std::size_t> queue;
  queue.push(0);
  seen[0] = 1;
  std::size_t reached = 1;
  while (!queue.empty()) {
    const std::size_t t = queue.front();
    queue.pop();
    for (int k = 0; k < 3; ++k) {
      const int a = poly.triangles[t][k], b = poly.triangles[t][(k + 1) % 3];
      for (std::size_t u : edges[key(a, b)]) {
        if (seen[u]) continue;
        if (has_directed(u, a, b)) std::swap(poly.triangles[u][1], poly.triangles[u][2]);
        seen[u] = 1;
        ++reached;
        queue.push(u);
      }
    }
  }
  if (reached != n) throw InputError(source + ": the convex hull is not one connected surface");

  double volume6 = 0;
  for (const auto& t : poly.triangles)
    volume6 += poly.vertices_m[t[0]].dot(poly.vertices_m[t[1]].cross(poly.vertices_m[t[2]]));
  if (volume6 < 0)
    for (auto& t : poly.triangles) std::swap(t[1], t[2]);
}

}  // namespace

std::array<std::size_t, 4> SpanningTetrahedron(const std::vector<Eigen::Vector3d>& points_m,
                                               const std::string& source) {
  const std::size_t n = points_m.size();
  if (n < 4) {
    std::ostringstream msg;
    msg << source << ": " << n << " point" << (n == 1 ? "" : "s")
        << "; a rock needs at least 4 points that are not coplanar";
    throw InputError(msg.str());
  }
  for (std::size_t i = 0; i < n; ++i)
    if (!(points_m[i].cwiseAbs().maxCoeff() <= kMaxCoordinate_m)) {  // NaN fails too
      std::ostringstream msg;
      msg << source << ": point " << i + 1 << " (" << points_m[i].transpose()
          << "): coordinates out of range (finite and within +-" << kMaxCoordinate_m
          << " m); not metres?";
      throw InputError(msg.str());
    }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : points_m) mean += p;
  mean /= static_cast<double>(n);

  double d = 0;
  const std::size_t i0 = Farthest(
      points_m, [&](const Eigen::Vector3d& p) { return (p - mean).norm(); }, &d);
  const Eigen::Vector3d& a = points_m[i0];
  double extent = 0;
  const std::size_t i1 = Farthest(
      points_m, [&](const Eigen::Vector3d& p) { return (p - a).norm(); }, &extent);
  std::ostringstream msg;
  msg << source << ": ";
  if (!(extent > 0)) {
    msg << "all " << n << " points coincide; a rock needs a 3-D scan";
    throw InputError(msg.str());
  }
  const Eigen::Vector3d axis = (points_m[i1] - a) / extent;
  const std::size_t i2 = Farthest(
      points_m, [&](const Eigen::Vector3d& p) { return (p - a).cross(axis).norm(); }, &d);
  if (d <= kDegenerateTolerance * extent) {
    msg << "all " << n << " points are collinear (within " << d << " m of a line " << extent
        << " m long); a rock needs a 3-D scan";
    throw InputError(msg.str());
  }
  const Eigen::Vector3d normal = (points_m[i1] - a).cross(points_m[i2] - a).normalized();
  const std::size_t i3 = Farthest(
      points_m, [&](const Eigen::Vector3d& p) { return std::abs((p - a).dot(normal)); }, &d);
  if (d <= kDegenerateTolerance * extent) {
    msg << "all " << n << " points are coplanar (within " << d << " m of a plane, extent " << extent
        << " m); a rock needs a 3-D scan";
    throw InputError(msg.str());
  }
  return {i0, i1, i2, i3};
}

Polyhedron ComputeConvexHull(const std::vector<Eigen::Vector3d>& points_m,
                             const std::string& source) {
  SpanningTetrahedron(points_m, source);

  // PCL works in single precision: hand it the points relative to their bounding-box centre.
  Eigen::Vector3d lo = points_m[0], hi = points_m[0];
  for (const auto& p : points_m) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->resize(points_m.size());
  for (std::size_t i = 0; i < points_m.size(); ++i) {
    const Eigen::Vector3d p = points_m[i] - centre;
    (*cloud)[i] = pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                static_cast<float>(p.z()));
  }
  // Area and volume stay off: with them on, PCL has qhull print statistics to stdout.
  pcl::ConvexHull<pcl::PointXYZ> qhull;
  qhull.setInputCloud(cloud);
  qhull.setDimension(3);
  qhull.setComputeAreaVolume(false);
  pcl::PointCloud<pcl::PointXYZ> hull_points;
  std::vector<pcl::Vertices> polygons;
  pcl::PointIndices hull_indices;
  {
    const QuietHullScope quiet;
    qhull.reconstruct(hull_points, polygons);
    qhull.getHullPointIndices(hull_indices);
  }
  if (polygons.empty() || hull_indices.indices.size() != hull_points.size())
    throw InputError(source + ": qhull could not compute the convex hull of " +
                     std::to_string(points_m.size()) + " points");

  // The hull's vertices are the input points themselves, in double precision.
  Polyhedron hull;
  hull.vertices_m.reserve(hull_indices.indices.size());
  for (const auto index : hull_indices.indices)
    hull.vertices_m.push_back(points_m[static_cast<std::size_t>(index)]);
  hull.triangles.reserve(polygons.size());
  for (const auto& polygon : polygons) {
    if (polygon.vertices.size() != 3) continue;
    const int a = static_cast<int>(polygon.vertices[0]), b = static_cast<int>(polygon.vertices[1]),
              c = static_cast<int>(polygon.vertices[2]);
    if (a == b || b == c || c == a) continue;
    hull.triangles.push_back({a, b, c});
  }
  OrientOutward(hull, source);
  return hull;
}

}  // namespace talus::pointclouds
