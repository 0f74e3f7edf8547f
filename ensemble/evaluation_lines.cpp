#include "ensemble/evaluation_lines.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace talus::ensemble {
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

struct Box {
  Eigen::Vector2d lo, hi;
  bool Overlaps(const Box& o) const {
    return lo.x() <= o.hi.x() && o.lo.x() <= hi.x() && lo.y() <= o.hi.y() && o.lo.y() <= hi.y();
  }
};

Box BoxOf(const std::vector<Eigen::Vector2d>& points) {
  Box box{points.front(), points.front()};
  for (const Eigen::Vector2d& p : points) {
    box.lo = box.lo.cwiseMin(p);
    box.hi = box.hi.cwiseMax(p);
  }
  return box;
}

// The lines and their bounding boxes, shared by the recorders of all threads.
struct PreparedLines {
  std::shared_ptr<const std::vector<EvaluationLine>> lines;
  std::vector<Box> boxes;
};

double RotationalEnergy(const RockShape& shape, const RockState& s) {
  const Eigen::Vector3d& w = s.angular_velocity_rad_s;
  return 0.5 * w.dot(shape.inertia_kg_m2.cwiseProduct(w));
}

class EvaluationLineRecorder : public RockRecorder {
 public:
  EvaluationLineRecorder(const Terrain& terrain, std::shared_ptr<const PreparedLines> prepared)
      : terrain_(terrain), prepared_(std::move(prepared)) {}

  void Begin(const RockOutcome& outcome) override {
    shape_ = outcome.shape.get();
    previous_ = outcome.start;
    const Eigen::Vector3d& p = previous_.position_m;
    if (!terrain_.Height(p.x(), p.y(), &previous_ground_m_))
      previous_ground_m_ = std::numeric_limits<double>::quiet_NaN();
    slot_.assign(prepared_->lines->size(), -1);
    crossings_.clear();
  }

  void OnStep(const RockState& state, const StepReport&, const TerrainSample& ground) override {
    const Eigen::Vector2d a = previous_.position_m.head<2>(), b = state.position_m.head<2>();
    const Box step{a.cwiseMin(b), a.cwiseMax(b)};
    const std::vector<EvaluationLine>& lines = *prepared_->lines;
    for (std::size_t l = 0; l < lines.size(); ++l) {
      if (!step.Overlaps(prepared_->boxes[l])) continue;
      const StepCrossing c = CrossPolyline(a, b, lines[l].vertices_m);
      if (c.count == 0) continue;
      if (slot_[l] < 0) {
        slot_[l] = static_cast<int>(crossings_.size());
        crossings_.push_back(At(previous_, state, ground.height_m, c.fraction));
        crossings_.back().line = static_cast<int>(l);
      }
      crossings_[static_cast<std::size_t>(slot_[l])].crossings += c.count;
    }
    previous_ = state;
    previous_ground_m_ = ground.height_m;
  }

  void Finish(RockOutcome& outcome) override {
    std::sort(crossings_.begin(), crossings_.end(),
              [](const LineCrossing& x, const LineCrossing& y) { return x.line < y.line; });
    outcome.line_crossings = std::move(crossings_);
    crossings_ = {};
  }

 private:
  // The crossing at fraction f of the step s0 -> s1 (ground_m: the terrain under s1).
  LineCrossing At(const RockState& s0, const RockState& s1, double ground_m, double f) const {
    LineCrossing c;
    c.t_s = s0.time_s + f * (s1.time_s - s0.time_s);
    c.position_m = s0.position_m + f * (s1.position_m - s0.position_m);
    const Eigen::Vector3d v = s0.velocity_m_s + f * (s1.velocity_m_s - s0.velocity_m_s);
    c.speed_m_s = v.norm();
    c.translational_energy_J = 0.5 * shape_->mass_kg * v.squaredNorm();
    const double e0 = RotationalEnergy(*shape_, s0), e1 = RotationalEnergy(*shape_, s1);
    c.rotational_energy_J = e0 + f * (e1 - e0);
    double here_m = 0;
    if (!terrain_.Height(c.position_m.x(), c.position_m.y(), &here_m)) {
      // A nodata cell between two valid ends of the step: the terrain between them.
      const double g0 = std::isnan(previous_ground_m_) ? ground_m : previous_ground_m_;
      here_m = g0 + f * (ground_m - g0);
    }
    c.com_height_m = c.position_m.z() - here_m;
    // Clearance: the lowest vertex above the terrain under it (under the centre of mass for a
    // vertex off the DEM), in the orientation interpolated along the step.
    const Eigen::Matrix3d rotation = s0.orientation.slerp(f, s1.orientation).toRotationMatrix();
    double clearance = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& vertex : shape_->vertices_m) {
      const Eigen::Vector3d x = c.position_m + rotation * vertex;
      double under_m = here_m;
      terrain_.Height(x.x(), x.y(), &under_m);
      clearance = std::min(clearance, x.z() - under_m);
    }
    c.bounce_height_m = std::max(0.0, clearance);
    return c;
  }

  const Terrain& terrain_;
  std::shared_ptr<const PreparedLines> prepared_;
  const RockShape* shape_ = nullptr;
  RockState previous_;
  double previous_ground_m_ = 0;
  std::vector<int> slot_;  // per line: index into crossings_, -1 while not crossed
  std::vector<LineCrossing> crossings_;
};

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

double EvaluationLine::length_m() const {
  double length = 0;
  for (std::size_t k = 1; k < vertices_m.size(); ++k)
    length += (vertices_m[k] - vertices_m[k - 1]).norm();
  return length;
}

RecorderFactory EvaluationLineRecorders(const Terrain& terrain,
                                        std::shared_ptr<const std::vector<EvaluationLine>> lines) {
  auto prepared = std::make_shared<PreparedLines>();
  for (const EvaluationLine& line : *lines) prepared->boxes.push_back(BoxOf(line.vertices_m));
  prepared->lines = std::move(lines);
  return [&terrain, prepared]() -> std::unique_ptr<RockRecorder> {
    return std::make_unique<EvaluationLineRecorder>(terrain, prepared);
  };
}

}  // namespace talus::ensemble
