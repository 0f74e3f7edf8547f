#include "ensemble/rasters.hpp"

#include <algorithm>
#include <cmath>

namespace talus::ensemble {

FootprintRecorder::FootprintRecorder(const RasterRequest& request, const Terrain& terrain)
    : request_(request),
      terrain_(terrain),
      slot_(static_cast<std::size_t>(request.grid.nx) * request.grid.ny, -1) {}

int FootprintRecorder::CellOf(double x_m, double y_m) const {
  const GridGeometry& g = request_.grid;
  const long i = std::lround((x_m - g.x0_m) / g.dx_m);
  const long j = std::lround((y_m - g.y0_m) / g.dy_m);
  if (i < 0 || j < 0 || i >= g.nx || j >= g.ny) return -1;
  return static_cast<int>(j * g.nx + i);
}

void FootprintRecorder::Mark(const Eigen::Vector3d& position, float speed, float energy,
                             float jump) {
  const int cell = CellOf(position.x(), position.y());
  if (cell < 0) return;
  int& slot = slot_[static_cast<std::size_t>(cell)];
  if (slot < 0) {
    slot = static_cast<int>(footprint_.cells.size());
    footprint_.cells.push_back(cell);
    if (request_.speed) footprint_.speed_m_s.push_back(speed);
    if (request_.energy) footprint_.energy_j.push_back(energy);
    if (request_.jump_height) footprint_.jump_height_m.push_back(jump);
    return;
  }
  const auto k = static_cast<std::size_t>(slot);
  if (request_.speed) footprint_.speed_m_s[k] = std::max(footprint_.speed_m_s[k], speed);
  if (request_.energy) footprint_.energy_j[k] = std::max(footprint_.energy_j[k], energy);
  if (request_.jump_height)
    footprint_.jump_height_m[k] = std::max(footprint_.jump_height_m[k], jump);
}

void FootprintRecorder::Begin(const RockOutcome& outcome) {
  const RockState& start = outcome.start;
  rock_ = outcome.shape.get();
  previous_ = start.position_m;
  if (!request_.needs_passes()) return;
  TerrainSample ground;
  const float jump =
      terrain_.Sample(start.position_m.x(), start.position_m.y(), &ground)
          ? static_cast<float>((start.position_m.z() - ground.height_m) * ground.normal.z())
          : 0.0f;
  Mark(start.position_m, static_cast<float>(start.velocity_m_s.norm()),
       static_cast<float>(KineticEnergy(*rock_, start)), jump);
}

void FootprintRecorder::OnStep(const RockState& state, const StepReport&,
                               const TerrainSample& ground) {
  if (!request_.needs_passes()) return;
  const auto speed = static_cast<float>(state.velocity_m_s.norm());
  const auto energy = request_.energy ? static_cast<float>(KineticEnergy(*rock_, state)) : 0.0f;
  const auto jump =
      static_cast<float>((state.position_m.z() - ground.height_m) * ground.normal.z());
  // A step longer than half a cell marks the cells in between too.
  const double half_cell = 0.5 * std::min(request_.grid.dx_m, request_.grid.dy_m);
  const double moved = (state.position_m - previous_).head<2>().norm();
  const int pieces = moved > half_cell ? static_cast<int>(std::ceil(moved / half_cell)) : 1;
  for (int k = 1; k < pieces; ++k)
    Mark(previous_ + (double(k) / pieces) * (state.position_m - previous_), speed, energy, jump);
  Mark(state.position_m, speed, energy, jump);
  previous_ = state.position_m;
}

void FootprintRecorder::Finish(RockOutcome& outcome) {
  for (int cell : footprint_.cells) slot_[static_cast<std::size_t>(cell)] = -1;
  outcome.footprint = std::move(footprint_);
  footprint_ = Footprint{};
  const RockResult& result = outcome.result;
  if (result.end == EndReason::kRest)
    outcome.footprint.deposit_cell =
        CellOf(result.final_state.position_m.x(), result.final_state.position_m.y());
}

RasterAccumulator::RasterAccumulator(const RasterRequest& request) : request_(request) {
  const auto cells = static_cast<std::size_t>(request.grid.nx) * request.grid.ny;
  if (request.passages || request.reach_probability) passages_.assign(cells, 0);
  if (request.deposits) deposits_.assign(cells, 0);
  for (auto [wanted, stat] :
       {std::pair{request.speed, &speed_}, std::pair{request.energy, &energy_},
        std::pair{request.jump_height, &jump_}}) {
    if (!wanted) continue;
    stat->max.assign(cells, 0.0f);
    stat->sum.assign(cells, 0.0);
    stat->values.assign(cells, {});
  }
}

void RasterAccumulator::AddStat(Stat& stat, int cell, float value) {
  const auto c = static_cast<std::size_t>(cell);
  stat.max[c] = stat.values[c].empty() ? value : std::max(stat.max[c], value);
  stat.sum[c] += value;
  stat.values[c].push_back(value);
}

void RasterAccumulator::Add(const Footprint& footprint) {
  ++rocks_;
  for (std::size_t k = 0; k < footprint.cells.size(); ++k) {
    const int cell = footprint.cells[k];
    if (!passages_.empty()) ++passages_[static_cast<std::size_t>(cell)];
    if (request_.speed) AddStat(speed_, cell, footprint.speed_m_s[k]);
    if (request_.energy) AddStat(energy_, cell, footprint.energy_j[k]);
    if (request_.jump_height) AddStat(jump_, cell, footprint.jump_height_m[k]);
  }
  if (!deposits_.empty() && footprint.deposit_cell >= 0)
    ++deposits_[static_cast<std::size_t>(footprint.deposit_cell)];
}

void RasterAccumulator::FinishStat(const Stat& stat, const std::string& name,
                                   const std::string& unit, std::vector<RasterLayer>& out) const {
  const std::size_t cells = stat.max.size();
  RasterLayer max{name + "_max", unit, std::vector<float>(cells, RasterLayer::kNoData), true};
  RasterLayer mean{name + "_mean", unit, std::vector<float>(cells, RasterLayer::kNoData), true};
  RasterLayer p95{name + "_p95", unit, std::vector<float>(cells, RasterLayer::kNoData), true};
  std::vector<float> sorted;
  for (std::size_t c = 0; c < cells; ++c) {
    const std::vector<float>& v = stat.values[c];
    if (v.empty()) continue;
    max.values[c] = stat.max[c];
    mean.values[c] = static_cast<float>(stat.sum[c] / static_cast<double>(v.size()));
    // Nearest-rank percentile: the smallest value with at least 95 % of the values at or below it.
    sorted = v;
    const auto rank = static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(v.size())));
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(rank - 1), sorted.end());
    p95.values[c] = sorted[rank - 1];
  }
  out.push_back(std::move(max));
  out.push_back(std::move(mean));
  out.push_back(std::move(p95));
}

std::vector<RasterLayer> RasterAccumulator::Finish() const {
  std::vector<RasterLayer> out;
  if (request_.speed) FinishStat(speed_, "speed", "m/s", out);
  if (request_.energy) FinishStat(energy_, "energy", "J", out);
  if (request_.jump_height) FinishStat(jump_, "jump_height", "m", out);
  const auto to_float = [](const std::vector<int>& counts) {
    return std::vector<float>(counts.begin(), counts.end());
  };
  if (request_.passages) out.push_back({"passages", "rocks", to_float(passages_), false});
  if (request_.deposits) out.push_back({"deposits", "rocks", to_float(deposits_), false});
  if (request_.reach_probability) {
    RasterLayer reach{"reach_probability", "1", std::vector<float>(passages_.size(), 0.0f), false};
    for (std::size_t c = 0; c < passages_.size(); ++c)
      reach.values[c] = rocks_ ? static_cast<float>(double(passages_[c]) / double(rocks_)) : 0.0f;
    out.push_back(std::move(reach));
  }
  return out;
}

}  // namespace talus::ensemble
