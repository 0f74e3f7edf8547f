#include "solver/barriers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "common/format.hpp"

namespace talus {
namespace {

// Where the step a -> b crosses the segment p -> q: the fraction along a -> b, or -1. The step is
// half-open at its start (a rock that ends a step on the segment crossed it in that step, not in
// the next one); the segment is closed, or half-open at q when `open_end`.
double SegmentCrossing(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p,
                       const Eigen::Vector2d& q, bool open_end) {
  const Eigen::Vector2d r = b - a, s = q - p;
  const double denominator = r.x() * s.y() - r.y() * s.x();
  if (denominator == 0) return -1;  // parallel (or a zero-length step or segment): no crossing
  const Eigen::Vector2d d = p - a;
  const double t = (d.x() * s.y() - d.y() * s.x()) / denominator;
  const double u = (d.x() * r.y() - d.y() * r.x()) / denominator;
  const bool on_segment = u >= 0 && (open_end ? u < 1 : u <= 1);
  return t > 0 && t <= 1 && on_segment ? t : -1;
}

double RotationalEnergy(const RockShape& shape, const RockState& s) {
  const Eigen::Vector3d& w = s.angular_velocity_rad_s;
  return 0.5 * w.dot(shape.inertia_kg_m2.cwiseProduct(w));
}

}  // namespace

StepCrossing CrossPolyline(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                           const std::vector<Eigen::Vector2d>& polyline) {
  StepCrossing out;
  for (std::size_t k = 1; k < polyline.size(); ++k) {
    const double t = SegmentCrossing(a, b, polyline[k - 1], polyline[k], k + 1 < polyline.size());
    if (t < 0) continue;
    ++out.count;
    if (out.fraction < 0 || t < out.fraction) out.fraction = t;
  }
  return out;
}

PointOnStep PointAlongStep(const Terrain& terrain, const RockShape& rock, const RockState& s0,
                           double ground0_m, const RockState& s1, double ground1_m, double f) {
  PointOnStep c;
  c.t_s = s0.time_s + f * (s1.time_s - s0.time_s);
  c.position_m = s0.position_m + f * (s1.position_m - s0.position_m);
  c.velocity_m_s = s0.velocity_m_s + f * (s1.velocity_m_s - s0.velocity_m_s);
  const double e0 = RotationalEnergy(rock, s0), e1 = RotationalEnergy(rock, s1);
  c.rotational_energy_J = e0 + f * (e1 - e0);
  if (!terrain.Height(c.position_m.x(), c.position_m.y(), &c.ground_m)) {
    // A nodata cell between two valid ends of the step: the terrain between them.
    const double g0 = std::isnan(ground0_m) ? ground1_m : ground0_m;
    c.ground_m = g0 + f * (ground1_m - g0);
  }
  c.com_height_m = c.position_m.z() - c.ground_m;
  // Clearance: the lowest vertex above the terrain under it (under the centre of mass for a
  // vertex off the DEM), in the orientation interpolated along the step.
  c.orientation = s0.orientation.slerp(f, s1.orientation);
  const Eigen::Matrix3d rotation = c.orientation.toRotationMatrix();
  double clearance = std::numeric_limits<double>::infinity();
  for (const Eigen::Vector3d& vertex : rock.vertices_m) {
    const Eigen::Vector3d x = c.position_m + rotation * vertex;
    double under_m = c.ground_m;
    terrain.Height(x.x(), x.y(), &under_m);
    clearance = std::min(clearance, x.z() - under_m);
  }
  c.clearance_m = std::max(0.0, clearance);
  return c;
}

const char* ToString(BarrierType type) {
  switch (type) {
    case BarrierType::kFlexibleNet:
      return "flexible_net";
    case BarrierType::kRigidWall:
      return "rigid_wall";
    case BarrierType::kDam:
      return "dam";
  }
  return "unknown";
}

bool ParseBarrierType(const std::string& name, BarrierType* type) {
  for (BarrierType t : {BarrierType::kFlexibleNet, BarrierType::kRigidWall, BarrierType::kDam}) {
    if (name != ToString(t)) continue;
    *type = t;
    return true;
  }
  return false;
}

const char* ToString(BarrierOutcome outcome) {
  switch (outcome) {
    case BarrierOutcome::kOvertopped:
      return "overtopped";
    case BarrierOutcome::kStopped:
      return "stopped";
    case BarrierOutcome::kBrokeThrough:
      return "broke_through";
  }
  return "unknown";
}

double Barrier::length_m() const {
  double length = 0;
  for (std::size_t k = 1; k < vertices_m.size(); ++k)
    length += (vertices_m[k] - vertices_m[k - 1]).norm();
  return length;
}

bool Barrier::IsValid(std::string* why) const {
  auto fail = [&](const std::string& what) {
    if (why) *why = what;
    return false;
  };
  if (name.empty()) return fail("name is empty");
  if (vertices_m.size() < 2)
    return fail("vertices: a barrier needs at least 2 vertices, it has " +
                std::to_string(vertices_m.size()));
  for (const Eigen::Vector2d& v : vertices_m)
    if (!v.allFinite()) return fail("vertices: a vertex is not finite");
  if (!(length_m() > 0)) return fail("vertices: the polyline has zero length");
  if (!(std::isfinite(height_m) && height_m >= 0))
    return fail("height_m = " + TenDigits(height_m) + " must be finite and >= 0 m");
  if (!(std::isfinite(capacity_J) && capacity_J > 0))
    return fail("capacity_J = " + TenDigits(capacity_J) + " must be finite and > 0 J");
  return true;
}

BarrierAction MeetBarriers(const std::vector<Barrier>& barriers, const Terrain& terrain,
                           const RockShape& rock, const RockState& s0, double ground0_m,
                           RockState* state, double ground1_m, std::vector<BarrierEvent>* events) {
  BarrierAction action;
  const Eigen::Vector2d a = s0.position_m.head<2>(), b = state->position_m.head<2>();
  // The barriers this step crosses for the first time, in the order it reaches them.
  std::vector<std::pair<double, int>> crossed;
  for (std::size_t k = 0; k < barriers.size(); ++k) {
    const StepCrossing c = CrossPolyline(a, b, barriers[k].vertices_m);
    if (c.count == 0) continue;
    const bool met = std::any_of(events->begin(), events->end(), [&](const BarrierEvent& e) {
      return e.barrier == static_cast<int>(k);
    });
    if (!met) crossed.emplace_back(c.fraction, static_cast<int>(k));
  }
  if (crossed.empty()) return action;
  std::sort(crossed.begin(), crossed.end());

  const RockState s1 = *state;
  double absorbed_J = 0;  // by the barriers the rock broke through earlier in this step
  for (const auto& [f, k] : crossed) {
    const Barrier& barrier = barriers[static_cast<std::size_t>(k)];
    const PointOnStep p = PointAlongStep(terrain, rock, s0, ground0_m, s1, ground1_m, f);
    // The energy at the crossing without the barriers: less what those met before took.
    const double translational_J = 0.5 * rock.mass_kg * p.velocity_m_s.squaredNorm();
    const double full_J = translational_J + p.rotational_energy_J;
    const double left = full_J > 0 ? std::max(0.0, full_J - absorbed_J) / full_J : 0.0;
    BarrierEvent& e = events->emplace_back();
    e.barrier = k;
    e.t_s = p.t_s;
    e.position_m = p.position_m;
    e.speed_m_s = std::sqrt(left) * p.velocity_m_s.norm();
    e.translational_energy_J = left * translational_J;
    e.rotational_energy_J = left * p.rotational_energy_J;
    e.passing_height_m = p.clearance_m;
    e.com_height_m = p.com_height_m;
    const double energy = e.energy_J();
    if (p.clearance_m > barrier.height_m) {
      e.outcome = BarrierOutcome::kOvertopped;
      e.energy_after_J = energy;
    } else if (energy <= barrier.capacity_J) {
      e.outcome = BarrierOutcome::kStopped;
      e.energy_after_J = 0;
      RockState& rest = *state;
      rest.position_m = p.position_m;
      rest.orientation = p.orientation;
      rest.time_s = p.t_s;
      rest.velocity_m_s.setZero();
      rest.angular_velocity_rad_s.setZero();
      action.acted = action.stopped = true;
      return action;
    } else {
      e.outcome = BarrierOutcome::kBrokeThrough;
      e.energy_after_J = energy - barrier.capacity_J;
      absorbed_J += barrier.capacity_J;
      action.acted = true;
    }
  }
  if (action.acted) {
    // The rock is at the step's end: it carries on with its energy there less what the barriers
    // took at their lines (the energy it would have had, had they taken it at the crossing, when
    // the forces between the crossing and the step's end do work that does not depend on the
    // speed: gravity, Coulomb friction). Its velocities keep their directions.
    const Eigen::Vector3d& w = state->angular_velocity_rad_s;
    const double end_J = 0.5 * rock.mass_kg * state->velocity_m_s.squaredNorm() +
                         0.5 * w.dot(rock.inertia_kg_m2.cwiseProduct(w));
    const double scale = end_J > 0 ? std::sqrt(std::max(0.0, end_J - absorbed_J) / end_J) : 0.0;
    state->velocity_m_s *= scale;
    state->angular_velocity_rad_s *= scale;
  }
  return action;
}

}  // namespace talus
