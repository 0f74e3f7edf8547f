#include "solver/contact_detection.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace talus {
namespace {

// The friction coefficient mu(s) of the step's scar on a ground category: the contacts of a step
// share the scar and mostly one category, so its arctangent is taken once per category met in a
// row.
class FrictionOfScar {
 public:
  FrictionOfScar(const GroundTable& table, double scar_m) : table_(table), scar_m_(scar_m) {}
  double operator()(int ground) {
    if (ground != ground_) {
      ground_ = ground;
      mu_ = table_.params(ground).Friction(scar_m_);
    }
    return mu_;
  }

 private:
  const GroundTable& table_;
  double scar_m_;
  int ground_ = -1;
  double mu_ = 0;
};

// Friction, ground and contact frame (n, t1, t2) of a contact at the terrain point (x, y).
void SetFrame(const Scene& scene, FrictionOfScar& friction, const Eigen::Vector3d& x,
              const Eigen::Vector3d& n, Contact& c) {
  c.ground = scene.terrain.GroundAt(x.x(), x.y());
  c.mu = friction(c.ground);
  // Tangent basis: e_y x n never vanishes for an upward normal.
  const Eigen::Vector3d t1 = Eigen::Vector3d(n.z(), 0.0, -n.x()).normalized();
  c.directions.col(0) = n;
  c.directions.col(1) = t1;
  c.directions.col(2) = n.cross(t1);
}

// Body-frame point where a predicted contact's percussion acts (SolverOptions::predicted_lever):
// the vertex b, or the vertex turned by the body angular velocity omega over the time its linear
// path takes from the midpoint (height gap_mid_m above the contact plane) to that plane (height
// gap_end_m < 0 after horizon_s).
Eigen::Vector3d PredictedLeverArm(PredictedLever lever, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& omega, double horizon_s, double gap_mid_m,
                                  double gap_end_m) {
  if (lever == PredictedLever::kMidpoint || gap_mid_m <= 0) return b;
  const double angle = omega.norm() * horizon_s * gap_mid_m / (gap_mid_m - gap_end_m);
  if (angle == 0) return b;
  return Eigen::AngleAxisd(angle, omega.normalized()) * b;
}

// A closed vertex's law stops it moving into its own face, not along it: past a concave change of
// the terrain (the foot of a slope) it may slide on below the next face, and nothing ever lifts it
// out. When the predicted end point, less any motion into the own face (where that law lets the
// vertex go at worst), lies on a face of another normal and deeper than allowed_depth_m below it,
// the vertex gets a second contact with that face, as a predicted contact (gap to its plane plus
// the allowed depth, never negative).
void AddCornerContact(const Scene& scene, FrictionOfScar& friction, const Eigen::Matrix3d& rotation,
                      const Eigen::Vector3d& velocity_m_s, const Eigen::Vector3d& omega_rad_s,
                      double horizon_s, double allowed_depth_m, int vertex,
                      const Eigen::Vector3d& b, const Eigen::Vector3d& x,
                      const Eigen::Vector3d& normal, StepWorkspace& workspace) {
  const Eigen::Vector3d move = horizon_s * (velocity_m_s + rotation * omega_rad_s.cross(b));
  const Eigen::Vector3d x_end = x + move - std::min(0.0, normal.dot(move)) * normal;
  // Not below the terrain at the end point: not deeper than allowed either.
  TerrainSample end;
  if (!scene.terrain.SampleBelow(x_end.x(), x_end.y(), x_end.z(), &end)) return;
  const Eigen::Vector3d& n = end.normal;
  if (n.dot(normal) >= 1 - 1e-12) return;  // the same face
  if ((x_end.z() - end.height_m) * n.z() >= -allowed_depth_m) return;
  const Eigen::Vector3d on_plane(x_end.x(), x_end.y(), end.height_m);
  Contact& c = workspace.contacts.emplace_back();
  c.vertex = vertex;
  c.corner = true;
  c.lever_m = b;
  c.gap_m = std::max(0.0, n.dot(x - on_plane) + allowed_depth_m);
  SetFrame(scene, friction, x_end, n, c);
}

// The lift along the unit normal n that the drift over the horizon h gives vertex b beyond the
// straight line of its velocity, the turn's h^2 / 2 w x (w x arm) to second order (a pivot turning
// at w lifts its vertex by h^2 w^2 R / 2 a step), when gravity presses the vertex into the terrain
// harder than the turn lifts it: n . g + n . w x (w x arm) < 0, the free normal acceleration of a
// vertex moving with the terrain (the angular acceleration of a free turn left out), whose sign
// decides whether the continuous contact keeps its load. Otherwise 0: a vertex the turn carries
// away (a strike, a fast pivot) keeps the plastic law. Contact::lift_m.
double TurnLift(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& omega_body,
                const Eigen::Vector3d& b, const Eigen::Vector3d& n, double gravity_m_s2,
                double horizon_s) {
  const double centripetal = n.dot(rotation * omega_body.cross(omega_body.cross(b)));
  if (centripetal <= 0 || centripetal >= gravity_m_s2 * n.z()) return 0;
  return 0.5 * horizon_s * horizon_s * centripetal;
}

// Hulls of at least this many vertices are walked over to their lowest vertices first, which may
// show that none can touch, or that few can: those are then searched from there instead of
// looped over, when they lie within this share of the hull's extent from the lowest vertex
// (DetectContacts).
constexpr int kWalkFrom = 48;
constexpr double kSearchShare = 0.05;

// b . d summed as Eigen sums it, (x + y) + z.
double Along(const Eigen::Vector3d& b, const Eigen::Vector3d& d) {
  return d.x() * b.x() + d.y() * b.y() + d.z() * b.z();
}

// The vertex of least b . d, walked over the hull's edges from `start`: on a convex polyhedron a
// vertex no lower than its neighbours is the lowest (up to round-off, which the caller's slack
// covers).
int WalkToLowest(const RockShape& rock, const Eigen::Vector3d& d, int start, double* lowest) {
  const Eigen::Vector3d* vertices = rock.vertices_m.data();
  int at = start;
  double least = Along(vertices[at], d);
  for (;;) {
    int next = at;
    for (int i = rock.neighbour_start[at]; i < rock.neighbour_start[at + 1]; ++i) {
      const int k = rock.neighbours[i];
      const double along = Along(vertices[k], d);
      if (along < least) {
        least = along;
        next = k;
      }
    }
    if (next == at) break;
    at = next;
  }
  *lowest = least;
  return at;
}

// workspace.candidates: in ascending order, every vertex b with b . d1 <= within1 or
// b . d2 <= within2, given the lowest vertex along each direction, lowest1 and lowest2. Each of the
// two sets is connected over the hull's edges (from any of its vertices a descending edge leads on
// to the lowest vertex), so their union is searched from those two, at a cost that grows with the
// vertices found, not with the hull.
void SearchFromLowest(const RockShape& rock, const Eigen::Vector3d& d1, double within1, int lowest1,
                      const Eigen::Vector3d& d2, double within2, int lowest2,
                      StepWorkspace& workspace) {
  std::vector<int>& found = workspace.candidates;
  std::vector<unsigned>& marks = workspace.marks;
  found.clear();
  if (marks.size() != rock.vertices_m.size() || workspace.stamp == ~0u) {
    marks.assign(rock.vertices_m.size(), 0);
    workspace.stamp = 0;
  }
  const unsigned stamp = ++workspace.stamp;
  const Eigen::Vector3d* vertices = rock.vertices_m.data();
  for (const int seed : {lowest1, lowest2}) {
    if (marks[seed] == stamp) continue;
    if (Along(vertices[seed], d1) > within1 && Along(vertices[seed], d2) > within2) continue;
    marks[seed] = stamp;
    found.push_back(seed);
  }
  // Breadth first, `found` doubling as the queue.
  for (std::size_t next = 0; next < found.size(); ++next) {
    const int at = found[next];
    for (int i = rock.neighbour_start[at]; i < rock.neighbour_start[at + 1]; ++i) {
      const int k = rock.neighbours[i];
      if (marks[k] == stamp) continue;
      const Eigen::Vector3d& b = vertices[k];
      if (Along(b, d1) > within1 && Along(b, d2) > within2) continue;
      marks[k] = stamp;
      found.push_back(k);
    }
  }
  std::sort(found.begin(), found.end());
}

// The detection's local plane of a hull of fewer than kWalkFrom vertices is taken over a box wider
// than the detection box by this many times the travel that box allows for over the horizon, and
// kept for the steps whose boxes lie inside it (LocalPlaneFor). Its bound is looser than the
// detection box's own, so more vertices come within reach: on hulls of many vertices (a scan on
// rough terrain) those extra tests cost more than the plane saves (bench/README.md, "A kept local
// plane").
constexpr double kKeptPlaneTravels = 4;

// The local plane of the detection box of half-width `reach` around (x, y) (Terrain::PlaneAround):
// the kept plane when the box lies inside the kept plane's box; else, with a margin > 0, a plane
// over the box widened by `margin`, which is kept, when that box still takes PlaneAround's exact
// bound (at most kExactCells cells a side) and lies on the DEM clear of nodata; else the plane over
// the box itself. A plane's bound over a box holds over every box inside it, so the contacts found
// do not depend on which plane is taken, only which vertices are tested against the terrain.
// *anchor_m: the point where the plane's `at` was sampled.
bool LocalPlaneFor(const Terrain& terrain, double x_m, double y_m, double reach, double margin,
                   StepWorkspace::KeptPlane& kept, Terrain::LocalPlane* plane,
                   Eigen::Vector2d* anchor_m) {
  if (kept.heights.get() == &terrain.heights() && std::abs(x_m - kept.x_m) + reach <= kept.half_m &&
      std::abs(y_m - kept.y_m) + reach <= kept.half_m) {
    *plane = kept.plane;
    *anchor_m = Eigen::Vector2d(kept.x_m, kept.y_m);
    return true;
  }
  *anchor_m = Eigen::Vector2d(x_m, y_m);
  const GridGeometry& grid = terrain.heights().grid;
  const double wide = reach + margin;
  if (margin > 0 && 2 * wide <= Terrain::kExactCells * std::min(grid.dx_m, grid.dy_m) &&
      terrain.PlaneAround(x_m, y_m, wide, &kept.plane)) {
    kept.heights = terrain.shared_heights();
    kept.x_m = x_m;
    kept.y_m = y_m;
    kept.half_m = wide * (1 - 1e-12);  // a box inside by more than the rounding of its edges
    *plane = kept.plane;
    return true;
  }
  kept.heights.reset();
  return terrain.PlaneAround(x_m, y_m, reach, plane);
}

}  // namespace

// Whether the terrain point (x, y) is over a soil category, and then in *depth_m the depth of the
// rebound plane below the surface there for a vertex that is below the surface, or predicted to be
// by the end of the horizon: the episode's depth, or, when this vertex is the rock's first to enter
// a layer, eq. 11's from the vertical speed of the predicted velocity (Lu et al. 2019).
bool SoilDepthAt(const Scene& scene, const RockShape& rock, double x_m, double y_m,
                 double vertical_speed_m_s, SoilContact& soil, double* depth_m) {
  const int ground = scene.terrain.GroundAt(x_m, y_m);
  const GroundParams& params = scene.ground.params(ground);
  if (!params.IsSoil()) return false;
  if (soil.ground < 0) {
    soil.ground = ground;
    soil.depth_m = params.PenetrationDepth(rock.mass_kg, std::min(0.0, vertical_speed_m_s));
  }
  *depth_m = soil.depth_m;
  return true;
}

DetectResult DetectContacts(const Scene& scene, const RockShape& rock, const RockState& mid,
                            const Eigen::Matrix3d& rotation, const Eigen::Vector3d& velocity_m_s,
                            const Eigen::Vector3d& omega_rad_s, double horizon_s,
                            double allowed_depth_m, StepWorkspace& workspace) {
  workspace.contacts.clear();
  // Soil: the episode goes on while some vertex is in the layer (or about to enter it).
  SoilContact& soil = workspace.soil;
  soil = SoilContact{mid.soil_ground, mid.soil_depth_m, false};
  bool in_soil = false;
  const bool any_soil = workspace.scene_has_soil;
  const Terrain& terrain = scene.terrain;
  const Eigen::Vector3d& r = mid.position_m;
  const double radius = rock.bounding_radius_m;

  // Vertical height of a point above the local plane is m . x + offset with m = (-h_x, -h_y, 1).
  // Over the horizon it changes at the rate m . (v + w x arm) = m . v + b . (m_body x W): the
  // prediction is linear in time, as the solver's contact velocities are.
  // The box holds every vertex at the midpoint and at its predicted end point.
  const double travel = horizon_s * (velocity_m_s.norm() + radius * omega_rad_s.norm());
  const double reach = radius + travel;
  const double margin =
      static_cast<int>(rock.vertices_m.size()) < kWalkFrom ? kKeptPlaneTravels * travel : 0.0;
  Terrain::LocalPlane plane;
  Eigen::Vector2d anchor;
  const bool local =
      LocalPlaneFor(terrain, r.x(), r.y(), reach, margin, workspace.kept_plane, &plane, &anchor);
  const Eigen::Vector3d m(-plane.slope_x, -plane.slope_y, 1.0);
  // m . (r - (anchor, h)): the height of the centre above the plane.
  const double centre_height = r.z() - (plane.at.height_m + plane.slope_x * (r.x() - anchor.x()) +
                                        plane.slope_y * (r.y() - anchor.y()));
  const double centre_rate = m.dot(velocity_m_s);
  const double lowest_rate = centre_rate - radius * m.norm() * omega_rad_s.norm();
  if (local && centre_height - radius * m.norm() + horizon_s * std::min(0.0, lowest_rate) >
                   plane.deviation_m) {
    soil = SoilContact{};
    return DetectResult::kClear;
  }
  FrictionOfScar friction(scene.ground, mid.scar_m);
  // Held contacts: the plastic law's only (Newton's law takes the begin velocities of closed
  // contacts; a held one's would rebound it from above the terrain).
  const bool hold =
      scene.options.contact_hold == ContactHold::kHeld && scene.options.normal_restitution == 0;
  const double gravity = scene.options.gravity_m_s2;
  const Eigen::Vector3d m_body = rotation.transpose() * m;
  const Eigen::Vector3d rate_lever = m_body.cross(omega_rad_s);

  const int vertex_count = static_cast<int>(rock.vertices_m.size());
  const Eigen::Vector3d* vertices = rock.vertices_m.data();
  // The lowest a vertex comes above the local plane over the horizon: its height at the midpoint
  // or, approaching, at the end of the horizon. The vertices that may touch come within the
  // terrain's departure of the plane.
  const auto lowest_of = [&](const Eigen::Vector3d& b) {
    const double rate = Along(b, rate_lever);
    return centre_height + Along(b, m_body) + horizon_s * std::min(0.0, centre_rate + rate);
  };
  // Tests vertex k against the terrain itself; false when it lies outside the domain.
  const auto test = [&](int k) -> bool {
    const Eigen::Vector3d& b = vertices[k];
    const Eigen::Vector3d arm = rotation * b;
    const Eigen::Vector3d x = r + arm;
    // The gap (x_z - h) n_z has the sign of x_z - h: the normal is needed only for contacts.
    Terrain::Cell cell;
    if (!terrain.Locate(x.x(), x.y(), &cell)) return false;
    const double height = Terrain::HeightIn(cell);
    if (std::isnan(height)) return false;  // a nodata corner
    // Over soil, the contact is with the rebound plane below the surface.
    double depth = 0;
    if (any_soil && x.z() <= height &&
        SoilDepthAt(scene, rock, x.x(), x.y(), velocity_m_s.z(), soil, &depth)) {
      in_soil = true;
      soil.submerged = true;
    }
    if (x.z() <= height - depth) {
      // Closed at the midpoint.
      const Eigen::Vector3d normal = terrain.NormalIn(cell);
      Contact& c = workspace.contacts.emplace_back();
      c.vertex = k;
      c.lever_m = b;
      c.gap_m = 0;
      if (hold && depth == 0)
        c.lift_m = TurnLift(rotation, omega_rad_s, b, normal, gravity, horizon_s);
      SetFrame(scene, friction, x, normal, c);
      if (horizon_s > 0 && depth == 0)
        AddCornerContact(scene, friction, rotation, velocity_m_s, omega_rad_s, horizon_s,
                         allowed_depth_m, k, b, x, normal, workspace);
      return true;
    }
    if (horizon_s == 0) return true;
    // Open: predicted to close when the vertex, moving for the horizon with its predicted
    // velocity, would end deeper than allowed_depth_m. The contact takes the terrain's tangent
    // plane at that end point (so that a vertex heading past a concave kink meets the face it
    // will hit); its gap is the midpoint vertex's distance to that plane plus the allowed depth.
    const Eigen::Vector3d x_end = x + horizon_s * (velocity_m_s + rotation * omega_rad_s.cross(b));
    // Not below the terrain at the end point (or leaving the DEM: the next step says so): neither
    // predicted nor held.
    TerrainSample end;
    if (!terrain.SampleBelow(x_end.x(), x_end.y(), x_end.z(), &end)) return true;
    const Eigen::Vector3d& n = end.normal;
    const double end_gap = (x_end.z() - end.height_m) * n.z();
    if (end_gap >= -allowed_depth_m) {
      // Not predicted; held if it was a contact in the step before and reaches the terrain by
      // the next midpoint (ContactHold::kHeld), outside the soil, whose contacts sink by design.
      if (!hold || end_gap >= 0 || static_cast<std::size_t>(k) >= workspace.last_closed.size() ||
          !workspace.last_closed[k])
        return true;
      if (any_soil && scene.ground.params(terrain.GroundAt(x_end.x(), x_end.y())).IsSoil())
        return true;
      const Eigen::Vector3d on_plane(x_end.x(), x_end.y(), end.height_m);
      Contact& c = workspace.contacts.emplace_back();
      c.vertex = k;
      c.gap_m = std::max(0.0, n.dot(x - on_plane));
      c.held = true;
      c.lift_m = TurnLift(rotation, omega_rad_s, b, n, gravity, horizon_s);
      c.lever_m = b;
      SetFrame(scene, friction, x_end, n, c);
      return true;
    }
    double depth_end = 0;
    if (any_soil &&
        SoilDepthAt(scene, rock, x_end.x(), x_end.y(), velocity_m_s.z(), soil, &depth_end)) {
      in_soil = true;
      if ((x_end.z() - end.height_m + depth_end) * n.z() >= -allowed_depth_m) return true;
    }
    const Eigen::Vector3d on_plane(x_end.x(), x_end.y(), end.height_m - depth_end);
    Contact& c = workspace.contacts.emplace_back();
    c.vertex = k;
    const double gap_mid = n.dot(x - on_plane);
    c.gap_m = std::max(0.0, gap_mid + allowed_depth_m);  // never a push out
    c.lever_m = PredictedLeverArm(scene.options.predicted_lever, b, omega_rad_s, horizon_s, gap_mid,
                                  n.dot(x_end - on_plane));
    SetFrame(scene, friction, x_end, n, c);
    return true;
  };

  // Hulls of many vertices: walks over the hull's edges, from where the last ones ended, find the
  // lowest vertex along the plane's normal and along that of the end points (the lowest heights
  // at the midpoint and at the end of the horizon, bounded by two linear functions of b); when
  // both are out of reach of the terrain, no vertex is (to round-off, which `slack` covers many
  // times over). When the vertices within reach lie in a thin cap of the hull, they are searched
  // for from those two; otherwise all are looped over. The walks are taken while they pay: after
  // a detection where no vertex came within reach (a rock near the terrain but not on it) or that
  // searched.
  bool none = false, searched = false;
  const bool walk = local && vertex_count >= kWalkFrom && !rock.neighbours.empty();
  if (walk && workspace.walk_pays) {
    const double slack = 1e-9 * (m.norm() * reach + std::abs(centre_height) +
                                 std::abs(plane.deviation_m) + horizon_s * std::abs(centre_rate));
    const double within1 = plane.deviation_m - centre_height + slack;
    const double within2 = within1 - horizon_s * centre_rate;
    const Eigen::Vector3d d2 = m_body + horizon_s * rate_lever;
    int* ends = workspace.walk_end;
    double lowest1 = 0, lowest2 = 0;
    ends[0] = WalkToLowest(rock, m_body, std::clamp(ends[0], 0, vertex_count - 1), &lowest1);
    ends[1] = WalkToLowest(rock, d2, std::clamp(ends[1], 0, vertex_count - 1), &lowest2);
    none = lowest1 > within1 && lowest2 > within2;
    const double cap = kSearchShare * 2 * radius * m.norm();
    if (!none && within1 - lowest1 < cap && within2 - lowest2 < cap) {
      SearchFromLowest(rock, m_body, within1, ends[0], d2, within2, ends[1], workspace);
      for (const int k : workspace.candidates)
        if (lowest_of(vertices[k]) <= plane.deviation_m && !test(k))
          return DetectResult::kOutsideDomain;
      searched = true;
    }
  }
  if (!none && !searched) {
    // In blocks of vertices: first the lowest height of each, a loop of plain arithmetic free of
    // calls that keeps the plane and the rates in registers, then the test of those that may
    // touch (every vertex without a local plane).
    bool any = false;
    constexpr int kBlock = 32;
    double lowest[kBlock];
    for (int first = 0; first < vertex_count; first += kBlock) {
      const int count = std::min(kBlock, vertex_count - first);
      for (int j = 0; j < count; ++j) lowest[j] = lowest_of(vertices[first + j]);
      for (int j = 0; j < count; ++j) {
        if (local && lowest[j] > plane.deviation_m) continue;
        any = true;
        if (!test(first + j)) return DetectResult::kOutsideDomain;
      }
    }
    workspace.walk_pays = !any;
  }
  if (!in_soil) soil = SoilContact{};
  return DetectResult::kOk;
}

}  // namespace talus
