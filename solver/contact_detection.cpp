#include "solver/contact_detection.hpp"

#include <cmath>

namespace talus {

DetectResult DetectContacts(const Scene& scene, const RockShape& rock, const RockState& mid,
                            const Eigen::Matrix3d& rotation, StepWorkspace& workspace) {
  workspace.contacts.clear();
  const Terrain& terrain = scene.terrain;
  const Eigen::Vector3d& r = mid.position_m;
  const double radius = rock.bounding_radius_m;

  // Vertical height of a point above the local plane is m . x + offset with m = (-h_x, -h_y, 1).
  Terrain::LocalPlane plane;
  const bool local = terrain.PlaneAround(r.x(), r.y(), radius, &plane);
  const Eigen::Vector3d m(-plane.slope_x, -plane.slope_y, 1.0);
  const double centre_height = r.z() - plane.at.height_m;  // m . (r - (x, y, h)) as x, y match
  if (local && centre_height - radius * m.norm() > plane.deviation_m) return DetectResult::kOk;
  const Eigen::Vector3d m_body = rotation.transpose() * m;

  const int vertex_count = static_cast<int>(rock.vertices_m.size());
  for (int k = 0; k < vertex_count; ++k) {
    if (local && centre_height + m_body.dot(rock.vertices_m[k]) > plane.deviation_m) continue;
    const Eigen::Vector3d arm = rotation * rock.vertices_m[k];
    const Eigen::Vector3d x = r + arm;
    // The gap (x_z - h) n_z has the sign of x_z - h: the normal is needed only for contacts.
    double height;
    if (!terrain.Height(x.x(), x.y(), &height)) return DetectResult::kOutsideDomain;
    if (x.z() > height) continue;
    TerrainSample sample;
    terrain.Sample(x.x(), x.y(), &sample);

    Contact& c = workspace.contacts.emplace_back();
    c.vertex = k;
    c.ground = terrain.GroundAt(x.x(), x.y());
    c.mu = scene.ground.params(c.ground).Friction(mid.scar_m);
    const Eigen::Vector3d& n = sample.normal;
    // Tangent basis: e_y x n never vanishes for an upward normal.
    const Eigen::Vector3d t1 = Eigen::Vector3d(n.z(), 0.0, -n.x()).normalized();
    c.directions.col(0) = n;
    c.directions.col(1) = t1;
    c.directions.col(2) = n.cross(t1);
  }
  return DetectResult::kOk;
}

}  // namespace talus
