#pragma once
// Evaluation lines (barrier design): polylines on the map where every rock that crosses is
// recorded at its first crossing (time, place, speed, energies, heights) and its crossings are
// counted. The crossing test along one step is shared with the zone observations of fieldobs/.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "ensemble/recorders.hpp"

namespace talus::ensemble {

// How the straight step a -> b (horizontal) crosses a polyline: the number of its segments the
// step crosses, and where along the step the first crossing lies.
struct StepCrossing {
  int count = 0;         // crossings within the step (0: none)
  double fraction = -1;  // of the earliest crossing along a -> b, in (0, 1]; -1 when none
};
// A step crosses a segment when the two intersect. The step is half-open at its start (a rock
// that ends a step on the line crossed it in that step, not again in the next; a start on the
// line is no crossing); segments are half-open at their end vertex (the last one closed), so a
// step through a vertex between two segments crosses once. A step parallel to a segment does not
// cross it (a grazing path).
StepCrossing CrossPolyline(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                           const std::vector<Eigen::Vector2d>& polyline);

// One evaluation line: a name and >= 2 vertices in map coordinates (m).
struct EvaluationLine {
  std::string name;
  std::vector<Eigen::Vector2d> vertices_m;
  double length_m() const;  // horizontal length of the polyline
};

// A recorder of every rock's crossings of `lines` over `terrain` (which must outlive the runs):
// RockOutcome::line_crossings (ensemble/outcome.hpp) gets one record per line crossed, in line
// order.
RecorderFactory EvaluationLineRecorders(const Terrain& terrain,
                                        std::shared_ptr<const std::vector<EvaluationLine>> lines);

}  // namespace talus::ensemble
