#include "ensemble/evaluation_lines.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace talus::ensemble {
namespace {

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
    const PointOnStep p =
        PointAlongStep(terrain_, *shape_, s0, previous_ground_m_, s1, ground_m, f);
    LineCrossing c;
    c.t_s = p.t_s;
    c.position_m = p.position_m;
    c.speed_m_s = p.velocity_m_s.norm();
    c.translational_energy_J = 0.5 * shape_->mass_kg * p.velocity_m_s.squaredNorm();
    c.rotational_energy_J = p.rotational_energy_J;
    c.com_height_m = p.com_height_m;
    c.bounce_height_m = p.clearance_m;
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
