#include "solver/forest.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>

#include "common/format.hpp"

namespace talus {
namespace {

double KineticEnergy(const RockShape& rock, const Eigen::Vector3d& v, const Eigen::Vector3d& w) {
  return 0.5 * rock.mass_kg * v.squaredNorm() + 0.5 * w.dot(rock.inertia_kg_m2.cwiseProduct(w));
}

double Cross(const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
}

// The convex hull of `points` in the plane, counter-clockwise, without collinear points
// (Andrew's monotone chain). Overwrites `points`' order.
void PlanHull(std::vector<Eigen::Vector2d>& points, std::vector<Eigen::Vector2d>* hull) {
  std::sort(points.begin(), points.end(), [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  hull->assign(2 * points.size(), Eigen::Vector2d::Zero());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    while (k >= 2 && Cross((*hull)[k - 2], (*hull)[k - 1], points[i]) <= 0) --k;
    (*hull)[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && Cross((*hull)[k - 2], (*hull)[k - 1], points[i]) <= 0) --k;
    (*hull)[k++] = points[i];
  }
  hull->resize(k > 1 ? k - 1 : k);
}

// Where the stem's axis c lies relative to the convex polygon: the nearest point q of its
// boundary and the signed distance (negative inside).
double PolygonDistance(const std::vector<Eigen::Vector2d>& polygon, const Eigen::Vector2d& c,
                       Eigen::Vector2d* nearest) {
  bool inside = polygon.size() >= 3;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Eigen::Vector2d& a = polygon[i];
    const Eigen::Vector2d& b = polygon[(i + 1) % polygon.size()];
    if (Cross(a, b, c) < 0) inside = false;
    const Eigen::Vector2d ab = b - a;
    const double length2 = ab.squaredNorm();
    const double t = length2 > 0 ? std::clamp((c - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
    const Eigen::Vector2d q = a + t * ab;
    const double d = (c - q).norm();
    if (d < best) {
      best = d;
      *nearest = q;
    }
  }
  return inside ? -best : best;
}

Eigen::Vector2d ProjectOnDisk(const Eigen::Vector2d& p, double radius) {
  const double norm = p.norm();
  return norm <= radius
             ? p
             : (radius > 0 ? Eigen::Vector2d(p * (radius / norm)) : Eigen::Vector2d::Zero());
}

}  // namespace

double BreakingLaw::Energy_J(double dbh_m) const {
  return factor * (coefficient_J * std::pow(100 * dbh_m, exponent));
}

bool TreeSpecies::IsValid(std::string* why) const {
  auto fail = [&](const std::string& what) {
    if (why) *why = what;
    return false;
  };
  if (name.empty() || std::any_of(name.begin(), name.end(), [](char c) {
        return std::iscntrl(static_cast<unsigned char>(c));
      }))
    return fail("name '" + name + "' must be non-empty, without control characters");
  if (!(std::isfinite(energy_factor) && energy_factor > 0))
    return fail("energy_factor = " + TenDigits(energy_factor) + " must be finite and > 0");
  if (energy_coefficient_J && !(std::isfinite(*energy_coefficient_J) && *energy_coefficient_J > 0))
    return fail("energy_coefficient_j = " + TenDigits(*energy_coefficient_J) +
                " must be finite and > 0 J");
  if (energy_exponent && !(std::isfinite(*energy_exponent) && *energy_exponent > 0))
    return fail("energy_exponent = " + TenDigits(*energy_exponent) + " must be finite and > 0");
  if (energy_factor != 1 && (energy_coefficient_J || energy_exponent))
    return fail("energy_factor = " + TenDigits(energy_factor) +
                " with a law of its own: a species scales the forest's law or has its own "
                "coefficient and exponent, not both");
  return true;
}

BreakingLaw ForestModel::Law(int k) const {
  if (k < 0) return BreakingLaw{1, energy_coefficient_J, energy_exponent};
  const TreeSpecies& s = species[static_cast<std::size_t>(k)];
  return BreakingLaw{s.energy_factor, s.energy_coefficient_J.value_or(energy_coefficient_J),
                     s.energy_exponent.value_or(energy_exponent)};
}

bool ForestModel::IsValid(std::string* why) const {
  auto fail = [&](const std::string& what) {
    if (why) *why = what;
    return false;
  };
  if (!(std::isfinite(stem_height_m) && stem_height_m > 0))
    return fail("stem_height_m = " + TenDigits(stem_height_m) + " must be finite and > 0 m");
  if (!(std::isfinite(friction) && friction >= 0))
    return fail("friction = " + TenDigits(friction) + " must be finite and >= 0");
  if (!(std::isfinite(energy_coefficient_J) && energy_coefficient_J > 0))
    return fail("energy_coefficient_j = " + TenDigits(energy_coefficient_J) +
                " must be finite and > 0 J");
  if (!(std::isfinite(energy_exponent) && energy_exponent > 0))
    return fail("energy_exponent = " + TenDigits(energy_exponent) + " must be finite and > 0");
  for (const TreeSpecies& s : species) {
    std::string reason;
    if (!s.IsValid(&reason)) return fail("species '" + s.name + "': " + reason);
    if (std::count_if(species.begin(), species.end(),
                      [&](const TreeSpecies& t) { return t.name == s.name; }) > 1)
      return fail("species '" + s.name + "' is declared twice");
  }
  return true;
}

Forest::Forest(std::vector<Stem> stems, const ForestModel& model)
    : stems_(std::move(stems)), model_(model) {
  if (stems_.empty()) return;
  double x1 = stems_.front().position_m.x(), y1 = stems_.front().position_m.y();
  x0_m_ = x1;
  y0_m_ = y1;
  for (const Stem& s : stems_) {
    // A species the model lacks (IsValid says so) breaks at NaN rather than reading past the list.
    capacity_J_.push_back(s.species < static_cast<int>(model_.species.size())
                              ? model_.BreakingEnergy_J(s.dbh_m, s.species)
                              : std::numeric_limits<double>::quiet_NaN());
    max_radius_m_ = std::max(max_radius_m_, 0.5 * s.dbh_m);
    x0_m_ = std::min(x0_m_, s.position_m.x());
    y0_m_ = std::min(y0_m_, s.position_m.y());
    x1 = std::max(x1, s.position_m.x());
    y1 = std::max(y1, s.position_m.y());
  }
  nx_ = static_cast<int>((x1 - x0_m_) / cell_m_) + 1;
  ny_ = static_cast<int>((y1 - y0_m_) / cell_m_) + 1;
  const std::size_t cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
  std::vector<int> cell_of(stems_.size());
  cell_start_.assign(cells + 1, 0);
  for (std::size_t k = 0; k < stems_.size(); ++k) {
    const int i = std::min(nx_ - 1, static_cast<int>((stems_[k].position_m.x() - x0_m_) / cell_m_));
    const int j = std::min(ny_ - 1, static_cast<int>((stems_[k].position_m.y() - y0_m_) / cell_m_));
    cell_of[k] = j * nx_ + i;
    ++cell_start_[static_cast<std::size_t>(cell_of[k]) + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) cell_start_[c + 1] += cell_start_[c];
  order_.assign(stems_.size(), 0);
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t k = 0; k < stems_.size(); ++k)
    order_[static_cast<std::size_t>(fill[static_cast<std::size_t>(cell_of[k])]++)] =
        static_cast<int>(k);
}

bool Forest::IsValid(std::string* why) const {
  if (!model_.IsValid(why)) return false;
  for (std::size_t k = 0; k < stems_.size(); ++k) {
    const Stem& s = stems_[k];
    if (!(s.position_m.allFinite() && std::isfinite(s.ground_m))) {
      if (why) *why = "tree " + std::to_string(k) + ": position or foot not finite";
      return false;
    }
    if (!(std::isfinite(s.dbh_m) && s.dbh_m > 0)) {
      if (why) *why = "tree " + std::to_string(k) + ": dbh = " + TenDigits(s.dbh_m) + " m must be > 0";
      return false;
    }
    if (s.species < -1 || s.species >= static_cast<int>(model_.species.size())) {
      if (why)
        *why = "tree " + std::to_string(k) + ": species " + std::to_string(s.species) +
               " is not one of the model's " + std::to_string(model_.species.size());
      return false;
    }
  }
  return true;
}

Eigen::Vector3d PlasticFrictionalImpulse(const RockShape& rock, const Eigen::Matrix3d& rotation,
                                         const Eigen::Vector3d& lever_m,
                                         const Eigen::Matrix3d& directions, double mu,
                                         Eigen::Vector3d* velocity, Eigen::Vector3d* omega) {
  const Eigen::Vector3d& a = lever_m;
  const Eigen::Vector3d inv_inertia = rock.inertia_kg_m2.cwiseInverse();
  Eigen::Matrix3d cross_a;
  cross_a << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  // K: the point's velocity change per unit percussion there (world); G in the contact frame.
  const Eigen::Matrix3d mobility =
      Eigen::Matrix3d::Identity() / rock.mass_kg -
      cross_a * rotation * inv_inertia.asDiagonal() * rotation.transpose() * cross_a;
  const Eigen::Matrix3d g = directions.transpose() * mobility * directions;
  const Eigen::Vector3d gamma = directions.transpose() * (*velocity + (rotation * *omega).cross(a));

  // Sticking: the point stops entirely, when the percussion that does so lies in the cone.
  Eigen::Vector3d p = -g.partialPivLu().solve(gamma);
  auto in_cone = [&](const Eigen::Vector3d& q) {
    return q.x() >= 0 && q.tail<2>().norm() <= mu * q.x() * (1 + 1e-12);
  };
  if (!in_cone(p)) {
    // Sliding: Gauss-Seidel of the proximal-point laws (normal then tangential), which for a
    // single contact converges to the point where the normal velocity is 0 and the tangential
    // percussion opposes the slip on the disk's rim.
    p.setZero();
    const double r_t = 1.0 / std::max(g(1, 1), g(2, 2));
    for (int sweep = 0; sweep < 2000; ++sweep) {
      const Eigen::Vector3d before = p;
      Eigen::Vector3d end = gamma + g * p;
      p.x() = std::max(0.0, p.x() - end.x() / g(0, 0));
      end = gamma + g * p;
      p.tail<2>() = ProjectOnDisk(p.tail<2>() - r_t * end.tail<2>(), mu * p.x());
      if ((p - before).norm() <= 1e-14 * p.norm()) break;
    }
  }
  // Never add energy, and take the normal velocity to 0: else the frictionless plastic impulse.
  const double gained_J = p.dot(gamma) + 0.5 * p.dot(g * p);
  const double end_normal = (gamma + g * p).x();
  const double scale = std::abs(gamma.x());
  if (!(gained_J <= 0 && std::abs(end_normal) <= 1e-9 * (1 + scale) && p.allFinite()))
    p = Eigen::Vector3d(-gamma.x() / g(0, 0), 0, 0);
  const Eigen::Vector3d percussion = directions * p;
  *velocity += percussion / rock.mass_kg;
  *omega += inv_inertia.cwiseProduct(rotation.transpose() * a.cross(percussion));
  return percussion;
}

bool MeetStems(const Forest& forest, const RockShape& rock, RockState* state,
               std::vector<StemHit>* hits) {
  const Eigen::Vector2d centre = state->position_m.head<2>();
  const double reach = rock.bounding_radius_m + forest.max_radius_m();
  const double lowest_possible_m = state->position_m.z() - rock.bounding_radius_m;
  const ForestModel& model = forest.model();
  // The rock's hull in world coordinates and its plan view, made when a stem is near.
  thread_local std::vector<Eigen::Vector2d> plan, polygon;
  thread_local std::vector<int> overlapping;
  bool hull_ready = false;
  double z_min = 0, z_max = 0;
  Eigen::Matrix3d rotation;
  overlapping.clear();
  bool acted = false;

  forest.ForEachNear(centre, reach, [&](int k) {
    const Stem& stem = forest.stems()[static_cast<std::size_t>(k)];
    const double radius = 0.5 * stem.dbh_m;
    const double top_m = stem.ground_m + model.stem_height_m;
    if ((stem.position_m - centre).norm() > rock.bounding_radius_m + radius) return;
    if (lowest_possible_m > top_m) return;
    auto record =
        std::find_if(hits->begin(), hits->end(), [k](const StemHit& h) { return h.stem == k; });
    if (record != hits->end() && record->broken) return;  // gone for this rock
    if (!hull_ready) {
      rotation = state->orientation.toRotationMatrix();
      plan.clear();
      z_min = std::numeric_limits<double>::infinity();
      z_max = -z_min;
      for (const Eigen::Vector3d& b : rock.vertices_m) {
        const Eigen::Vector3d x = rotation * b;  // from the centre of mass
        plan.push_back(state->position_m.head<2>() + x.head<2>());
        z_min = std::min(z_min, state->position_m.z() + x.z());
        z_max = std::max(z_max, state->position_m.z() + x.z());
      }
      PlanHull(plan, &polygon);
      hull_ready = true;
    }
    if (z_min > top_m || z_max < stem.ground_m) return;
    Eigen::Vector2d q;
    const double distance = PolygonDistance(polygon, stem.position_m, &q);
    if (distance >= radius) return;
    overlapping.push_back(k);
    // Normal: horizontal, from the stem into the rock.
    Eigen::Vector2d n2 =
        distance >= 0 ? Eigen::Vector2d(q - stem.position_m) : Eigen::Vector2d(stem.position_m - q);
    if (!(n2.norm() > 0)) n2 = centre - stem.position_m;
    if (!(n2.norm() > 0)) return;
    n2.normalize();
    Eigen::Matrix3d directions;
    directions.col(0) = Eigen::Vector3d(n2.x(), n2.y(), 0);
    directions.col(1) = Eigen::Vector3d(-n2.y(), n2.x(), 0);
    directions.col(2) = Eigen::Vector3d::UnitZ();
    // Where it acts: the hull's nearest point in plan view, at the height of the centre of mass
    // within the part of the rock that the stem spans.
    const double z_c =
        std::clamp(state->position_m.z(), std::max(stem.ground_m, z_min), std::min(top_m, z_max));
    const Eigen::Vector3d lever = Eigen::Vector3d(q.x(), q.y(), z_c) - state->position_m;
    const Eigen::Vector3d omega_world = rotation * state->angular_velocity_rad_s;
    const double approach = directions.col(0).dot(state->velocity_m_s + omega_world.cross(lever));
    if (!(approach < 0)) return;  // separating or sliding past

    const double energy_J = KineticEnergy(rock, state->velocity_m_s, state->angular_velocity_rad_s);
    Eigen::Vector3d v = state->velocity_m_s, w = state->angular_velocity_rad_s;
    PlasticFrictionalImpulse(rock, rotation, lever, directions, model.friction, &v, &w);
    const double taken_J = std::max(0.0, energy_J - KineticEnergy(rock, v, w));
    if (record == hits->end()) {
      StemHit& h = hits->emplace_back();
      h.stem = k;
      h.stem_m = stem.position_m;
      h.t_s = state->time_s;
      h.position_m = state->position_m;
      h.energy_J = energy_J;
      record = hits->end() - 1;
    }
    if (!record->touching) ++record->impacts;
    record->touching = true;
    const double left_J = forest.capacity_J(k) - record->absorbed_J;
    if (taken_J <= left_J) {
      // The stem holds: the plastic impact.
      state->velocity_m_s = v;
      state->angular_velocity_rad_s = w;
      record->absorbed_J += taken_J;
    } else {
      // It breaks: the rock keeps its directions with its energy less what the stem had left.
      const double scale =
          energy_J > 0 ? std::sqrt(std::max(0.0, energy_J - left_J) / energy_J) : 0.0;
      state->velocity_m_s *= scale;
      state->angular_velocity_rad_s *= scale;
      record->absorbed_J = forest.capacity_J(k);
      record->broken = true;
    }
    acted = true;
  });
  // Episodes: a stem the hull no longer overlaps is free for a new impact.
  for (StemHit& h : *hits)
    h.touching =
        !h.broken && std::find(overlapping.begin(), overlapping.end(), h.stem) != overlapping.end();
  return acted;
}

ForestDrag::ForestDrag(GridGeometry grid, std::vector<int> cells, std::vector<DragStand> stands,
                       double height_m)
    : grid_(grid), cells_(std::move(cells)), stands_(std::move(stands)), height_m_(height_m) {}

const DragStand* ForestDrag::StandAt(double x_m, double y_m) const {
  const double u = std::floor((x_m - grid_.x0_m) / grid_.dx_m + 0.5);
  const double v = std::floor((y_m - grid_.y0_m) / grid_.dy_m + 0.5);
  if (!(u >= 0 && u < grid_.nx && v >= 0 && v < grid_.ny)) return nullptr;
  const int k = cells_[static_cast<std::size_t>(v) * static_cast<std::size_t>(grid_.nx) +
                       static_cast<std::size_t>(u)];
  return k >= 0 ? &stands_[static_cast<std::size_t>(k)] : nullptr;
}

bool ForestDrag::IsValid(std::string* why) const {
  auto fail = [&](const std::string& what) {
    if (why) *why = "drag: " + what;
    return false;
  };
  if (empty()) return true;
  if (!grid_.IsValid(why)) return false;
  if (cells_.size() != static_cast<std::size_t>(grid_.nx) * static_cast<std::size_t>(grid_.ny))
    return fail("the grid has " + std::to_string(cells_.size()) + " cells, expected nx * ny");
  if (!(std::isfinite(height_m_) && height_m_ > 0))
    return fail("height_m = " + TenDigits(height_m_) + " must be finite and > 0 m");
  for (int k : cells_)
    if (k < -1 || k >= static_cast<int>(stands_.size()))
      return fail("a cell refers to stand " + std::to_string(k) + ", not in the list");
  for (std::size_t k = 0; k < stands_.size(); ++k) {
    const DragStand& s = stands_[k];
    if (!(std::isfinite(s.stems_per_m2) && s.stems_per_m2 > 0 && std::isfinite(s.dbh_m) &&
          s.dbh_m > 0 && std::isfinite(s.breaking_energy_J) && s.breaking_energy_J > 0))
      return fail("stand " + std::to_string(k) + ": density " + TenDigits(s.stems_per_m2) +
                  " /m^2, dbh " + TenDigits(s.dbh_m) + " m and breaking energy " +
                  TenDigits(s.breaking_energy_J) + " J must be finite and > 0");
  }
  return true;
}

double ForestDrag::RockWidth_m(const RockShape& rock) {
  return std::cbrt(6 * rock.volume_m3 / std::numbers::pi);
}

double ForestDrag::Rate_1_s(const DragStand& stand, const RockShape& rock, const RockState& begin) {
  const double energy_J = KineticEnergy(rock, begin.velocity_m_s, begin.angular_velocity_rad_s);
  if (!(energy_J > 0)) return 0;
  const double hits_per_m = stand.stems_per_m2 * (stand.dbh_m + RockWidth_m(rock));
  const double per_hit_J = std::min(stand.breaking_energy_J, kPlasticShare * energy_J);
  return hits_per_m * begin.velocity_m_s.head<2>().norm() * per_hit_J / (2 * energy_J);
}

double ForestDragRate_1_s(const ForestDrag& drag, const RockShape& rock, const RockState& begin,
                          const Eigen::Vector3d& centre, double above_m) {
  if (above_m > drag.height_m()) return 0;
  const DragStand* stand = drag.StandAt(centre.x(), centre.y());
  return stand ? ForestDrag::Rate_1_s(*stand, rock, begin) : 0.0;
}

}  // namespace talus
