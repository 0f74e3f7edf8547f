#pragma once
// Evaluation lines (barrier design): polylines on the map where every rock that crosses is
// recorded at its first crossing (time, place, speed, energies, heights) and its crossings are
// counted. The crossing test along one step and the crossing point are those of the barriers
// (solver/barriers.hpp), and the crossing test is shared with the zone observations of fieldobs/.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "ensemble/recorders.hpp"
#include "solver/barriers.hpp"

namespace talus::ensemble {

// How the straight step a -> b (horizontal) crosses a polyline (solver/barriers.hpp).
using talus::CrossPolyline;
using talus::StepCrossing;

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
