#include "solver/contact_detection.hpp"

#include <cmath>

namespace talus {

DetectResult DetectContacts(const Scene& scene, const RockState& mid,
                            const Eigen::Matrix3d& rotation, StepWorkspace& workspace) {
  workspace.contacts.clear();
  const RockShape& rock = scene.rock;
  const Terrain& terrain = scene.terrain;
  const Eigen::Vector3d& r = mid.position_m;
  const double radius = rock.bounding_radius_m;
  if (r.z() - radius > terrain.MaxHeightAround(r.x(), r.y(), radius)) return DetectResult::kOk;

  const int vertex_count = static_cast<int>(rock.vertices_m.size());
  for (int k = 0; k < vertex_count; ++k) {
    const Eigen::Vector3d arm = rotation * rock.vertices_m[k];
    const Eigen::Vector3d x = r + arm;
    TerrainSample sample;
    if (!terrain.Sample(x.x(), x.y(), &sample)) return DetectResult::kOutsideDomain;
    const double gap = (x.z() - sample.height_m) * sample.normal.z();
    if (gap > 0) continue;

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
