#include "solver/soil.hpp"

#include <algorithm>
#include <array>
#include <limits>

namespace talus {

double SubmergedPart::FrontalArea(const Eigen::Vector3d& u) const {
  double area = std::max(0.0, cut_area.dot(u));
  for (const Eigen::Vector3d& a : face_areas) area += std::max(0.0, a.dot(u));
  return area;
}

void ClipBelowPlane(const RockShape& rock, const Eigen::Matrix3d& rotation,
                    const Eigen::Vector3d& plane_point_m, const Eigen::Vector3d& normal,
                    SubmergedPart* part, const Eigen::Vector3d& along) {
  part->volume_m3 = 0;
  part->centroid_m.setZero();
  part->depth_m = 0;
  part->face_areas.clear();
  part->cut_area.setZero();
  part->rear_m.setZero();
  part->front_m.setZero();
  // Vertices relative to the plane point; their heights above the plane.
  const std::size_t n = rock.vertices_m.size();
  std::vector<Eigen::Vector3d>& points = part->scratch_points;
  std::vector<double>& heights = part->scratch_heights;
  points.resize(n);
  heights.resize(n);
  bool any = false;
  for (std::size_t k = 0; k < n; ++k) {
    points[k] = rotation * rock.vertices_m[k] - plane_point_m;
    heights[k] = normal.dot(points[k]);
    if (heights[k] < 0) {
      any = true;
      part->depth_m = std::max(part->depth_m, -heights[k]);
    }
  }
  if (!any) return;
  // Rear and front: the extremes along `along` are at vertices below the plane or where an edge
  // crosses it, the corners the clipped polygons below have.
  double rear = std::numeric_limits<double>::infinity(), front = -rear;
  auto extent = [&](const Eigen::Vector3d& p) {
    const double at = along.dot(p);
    if (at < rear) {
      rear = at;
      part->rear_m = p;
    }
    if (at > front) {
      front = at;
      part->front_m = p;
    }
  };

  Eigen::Vector3d moment = Eigen::Vector3d::Zero();  // sum of volume times centroid
  Eigen::Vector3d closure = Eigen::Vector3d::Zero();
  for (const std::array<int, 3>& t : rock.triangles) {
    const double h0 = heights[t[0]], h1 = heights[t[1]], h2 = heights[t[2]];
    if (h0 >= 0 && h1 >= 0 && h2 >= 0) continue;
    // Sutherland-Hodgman against one plane: a triangle keeps at most four corners.
    std::array<Eigen::Vector3d, 4> polygon;
    int corners = 0;
    for (int e = 0; e < 3; ++e) {
      const int i = t[e], j = t[(e + 1) % 3];
      if (heights[i] < 0) polygon[corners++] = points[i];
      if ((heights[i] < 0) != (heights[j] < 0)) {
        const double s = heights[i] / (heights[i] - heights[j]);
        polygon[corners++] = points[i] + s * (points[j] - points[i]);
      }
    }
    for (int c = 0; c < corners; ++c) extent(polygon[c]);
    Eigen::Vector3d area = Eigen::Vector3d::Zero();
    for (int c = 1; c + 1 < corners; ++c) {
      const Eigen::Vector3d& a = polygon[0];
      const Eigen::Vector3d& b = polygon[c];
      const Eigen::Vector3d& d = polygon[c + 1];
      const Eigen::Vector3d cross = b.cross(d);
      area += 0.5 * (a.cross(b) + cross + d.cross(a));
      // Tetrahedron (plane point, a, b, d): the plane point is the origin here.
      const double volume = a.dot(cross) / 6.0;
      part->volume_m3 += volume;
      moment += volume * (a + b + d) / 4.0;
    }
    part->face_areas.push_back(area);
    closure += area;
  }
  part->cut_area = -closure;
  part->rear_m += plane_point_m;
  part->front_m += plane_point_m;
  if (part->volume_m3 > 0) part->centroid_m = plane_point_m + moment / part->volume_m3;
}

}  // namespace talus
