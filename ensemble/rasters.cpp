#include "ensemble/rasters.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <istream>
#include <ostream>
#include <utility>

#include "common/rounding.hpp"

namespace talus::ensemble {

namespace {

constexpr std::array<const char*, 7> kRasterKinds = {
    "speed", "energy", "jump_height", "passages", "deposits", "reach_probability", "tree_hits"};
// RasterRequest's flag of each kind, in RasterKind's order.
constexpr std::array<bool RasterRequest::*, 7> kRasterFlags = {
    &RasterRequest::speed,    &RasterRequest::energy,   &RasterRequest::jump_height,
    &RasterRequest::passages, &RasterRequest::deposits, &RasterRequest::reach_probability,
    &RasterRequest::tree_hits};

}  // namespace

constinit const EnumNames kRasterKindNames{"raster", kRasterKinds};

const char* ToString(RasterKind kind) { return kRasterKindNames.NameOf(kind); }

bool& RasterRequest::Wants(RasterKind kind) {
  return this->*kRasterFlags[static_cast<std::size_t>(kind)];
}
bool RasterRequest::Wants(RasterKind kind) const {
  return this->*kRasterFlags[static_cast<std::size_t>(kind)];
}

FootprintRecorder::FootprintRecorder(const RasterRequest& request, const Terrain& terrain)
    : request_(request),
      terrain_(terrain),
      slot_(static_cast<std::size_t>(request.grid.nx) * request.grid.ny, -1) {}

int FootprintRecorder::CellOf(double x_m, double y_m) const {
  const GridGeometry& g = request_.grid;
  // The nearest node (std::lround without its call: a step's mark takes two).
  const long i = RoundHalfAway((x_m - g.x0_m) / g.dx_m);
  const long j = RoundHalfAway((y_m - g.y0_m) / g.dy_m);
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
  // A step longer than half a cell marks the cells in between too. Most steps move less than half
  // of that, which their squared length shows without a root.
  const double half_cell = 0.5 * std::min(request_.grid.dx_m, request_.grid.dy_m);
  const double moved2 = (state.position_m - previous_).head<2>().squaredNorm();
  const double moved = moved2 < 0.25 * half_cell * half_cell ? 0.0 : std::sqrt(moved2);
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
  // At rest where it ended: on the ground, or held by a barrier at its line.
  if (result.end == EndReason::kRest || result.end == EndReason::kBarrier)
    outcome.footprint.deposit_cell =
        CellOf(result.final_state.position_m.x(), result.final_state.position_m.y());
  // Impacts on stems, in the cell of each stem.
  if (request_.tree_hits)
    for (const StemHit& h : result.stem_hits) {
      const int cell = CellOf(h.stem_m.x(), h.stem_m.y());
      if (cell >= 0)
        outcome.footprint.tree_hit_cells.insert(outcome.footprint.tree_hit_cells.end(),
                                                static_cast<std::size_t>(h.impacts), cell);
    }
}

RasterAccumulator::RasterAccumulator(const RasterRequest& request, RasterSpillOptions spill)
    : request_(request) {
  const auto cells = static_cast<std::size_t>(request.grid.nx) * request.grid.ny;
  if (quantities() > 0 && !request.percentiles.empty())
    spill_.emplace(request.grid, quantities(), std::move(spill));
  if (request.passages || request.reach_probability || spill_) passages_.assign(cells, 0);
  if (request.deposits) deposits_.assign(cells, 0);
  if (request.tree_hits) tree_hits_.assign(cells, 0);
  if (quantities() > 0) slot_.assign(cells, -1);
}

int RasterAccumulator::quantities() const {
  return int(request_.speed) + int(request_.energy) + int(request_.jump_height);
}

ValueSummary* RasterAccumulator::Summaries(int cell) {
  int& slot = slot_[static_cast<std::size_t>(cell)];
  if (slot < 0) {
    slot = static_cast<int>(summaries_.size());
    summaries_.resize(summaries_.size() + static_cast<std::size_t>(quantities()));
  }
  return &summaries_[static_cast<std::size_t>(slot)];
}

void RasterAccumulator::Add(const Footprint& footprint) {
  ++rocks_;
  for (std::size_t k = 0; k < footprint.cells.size(); ++k) {
    const int cell = footprint.cells[k];
    if (!passages_.empty()) ++passages_[static_cast<std::size_t>(cell)];
    if (slot_.empty()) continue;
    std::array<float, 3> values{};
    int q = 0;
    if (request_.speed) values[static_cast<std::size_t>(q++)] = footprint.speed_m_s[k];
    if (request_.energy) values[static_cast<std::size_t>(q++)] = footprint.energy_j[k];
    if (request_.jump_height) values[static_cast<std::size_t>(q++)] = footprint.jump_height_m[k];
    ValueSummary* s = Summaries(cell);
    for (int v = 0; v < q; ++v) s[v].Add(values[static_cast<std::size_t>(v)]);
    if (spill_) spill_->Append(cell, values.data());
  }
  if (!deposits_.empty() && footprint.deposit_cell >= 0)
    ++deposits_[static_cast<std::size_t>(footprint.deposit_cell)];
  if (!tree_hits_.empty())
    for (int cell : footprint.tree_hit_cells) ++tree_hits_[static_cast<std::size_t>(cell)];
}

void RasterAccumulator::Merge(const RasterAccumulator& other) {
  const auto q = static_cast<std::size_t>(quantities());
  rocks_ += other.rocks_;
  for (std::size_t c = 0; c < passages_.size(); ++c) passages_[c] += other.passages_[c];
  for (std::size_t c = 0; c < deposits_.size(); ++c) deposits_[c] += other.deposits_[c];
  for (std::size_t c = 0; c < tree_hits_.size(); ++c) tree_hits_[c] += other.tree_hits_[c];
  for (std::size_t c = 0; c < other.slot_.size(); ++c) {
    if (other.slot_[c] < 0) continue;
    ValueSummary* mine = Summaries(static_cast<int>(c));
    const ValueSummary* theirs = &other.summaries_[static_cast<std::size_t>(other.slot_[c])];
    for (std::size_t k = 0; k < q; ++k) mine[k].Merge(theirs[k]);
  }
  if (spill_) spill_->Append(*other.spill_);
}

namespace {

// "1st", "2nd", "3rd", "4th", ..., "11th", "12th", "13th", ..., "21st", ...
std::string Ordinal(int n) {
  const int tens = n % 100, ones = n % 10;
  const char* suffix = (tens >= 11 && tens <= 13) ? "th"
                       : ones == 1                ? "st"
                       : ones == 2                ? "nd"
                       : ones == 3                ? "rd"
                                                  : "th";
  return std::to_string(n).append(suffix);
}

}  // namespace

bool RasterRequest::IsValid(std::string* why) const {
  for (std::size_t k = 0; k < percentiles.size(); ++k) {
    const int p = percentiles[k];
    const char* reason = p < 1 || p > 99                    ? "must each be in 1 .. 99"
                         : k > 0 && p <= percentiles[k - 1] ? "must be ascending without repeats"
                                                            : nullptr;
    if (reason) {
      if (why) *why = "percentiles = " + std::to_string(p) + " " + reason;
      return false;
    }
  }
  return true;
}

std::vector<RasterLayer> RasterAccumulator::Finish(const Heightfield& dem) {
  const std::size_t cells = static_cast<std::size_t>(request_.grid.nx) * request_.grid.ny;
  assert(dem.grid.nx == request_.grid.nx && dem.grid.ny == request_.grid.ny &&
         dem.z_m.size() == cells);
  std::vector<RasterLayer> out;
  const auto layer = [&](const std::string& quantity, const std::string& statistic,
                         const std::string& unit, const std::string& description, float fill) {
    const std::string name =
        statistic == "count" || statistic == "fraction" ? quantity : quantity + "_" + statistic;
    return RasterLayer{name,     unit,      std::vector<float>(cells, fill),
                       quantity, statistic, description};
  };
  // The percentiles of every quantity from the spill: [quantity * percentiles + k][cell].
  const std::size_t percentiles = request_.percentiles.size();
  std::vector<std::vector<float>> spilled;
  if (spill_) {
    spilled.assign(static_cast<std::size_t>(quantities()) * percentiles,
                   std::vector<float>(cells, RasterLayer::kNoData));
    spill_->Percentiles(passages_, request_.percentiles, spilled);
  }
  int quantity = 0;
  for (auto [kind, unit] :
       {std::pair{RasterKind::kSpeed, "m/s"}, std::pair{RasterKind::kEnergy, "J"},
        std::pair{RasterKind::kJumpHeight, "m"}}) {
    if (!request_.Wants(kind)) continue;
    const std::string what = ToString(kind);
    const std::string shown = kind == RasterKind::kJumpHeight ? "jump height" : what;
    const std::size_t first = out.size();
    out.push_back(
        layer(what, "max", unit, shown + ", largest over passing rocks", RasterLayer::kNoData));
    out.push_back(
        layer(what, "mean", unit, shown + ", mean over passing rocks", RasterLayer::kNoData));
    for (std::size_t k = 0; k < percentiles; ++k) {
      const int p = request_.percentiles[k];
      const std::string statistic = std::string("p").append(std::to_string(p));
      const std::string description = shown + ", " + Ordinal(p) + " percentile over passing rocks";
      out.push_back(RasterLayer{what + "_" + statistic, unit,
                                std::move(spilled[static_cast<std::size_t>(quantity) *
                                                      percentiles + k]),
                                what, statistic, description});
    }
    for (std::size_t c = 0; c < cells; ++c) {
      if (slot_[c] < 0) continue;
      const ValueSummary& s =
          summaries_[static_cast<std::size_t>(slot_[c]) + static_cast<std::size_t>(quantity)];
      if (s.count() == 0) continue;
      out[first].values[c] = s.max();
      out[first + 1].values[c] = static_cast<float>(s.mean());
    }
    ++quantity;
  }
  if (request_.passages) {
    out.push_back(layer(ToString(RasterKind::kPassages), "count", "count",
                        "passages, rocks that passed the cell", 0));
    std::copy(passages_.begin(), passages_.end(), out.back().values.begin());
    out.back().counts.assign(passages_.begin(), passages_.end());
  }
  if (request_.deposits) {
    out.push_back(layer(ToString(RasterKind::kDeposits), "count", "count",
                        "deposits, rocks at rest in the cell", 0));
    std::copy(deposits_.begin(), deposits_.end(), out.back().values.begin());
    out.back().counts.assign(deposits_.begin(), deposits_.end());
  }
  if (request_.reach_probability) {
    out.push_back(layer(ToString(RasterKind::kReachProbability), "fraction", "1",
                        "reach probability, fraction of all rocks that passed the cell", 0));
    for (std::size_t c = 0; c < cells; ++c)
      out.back().values[c] =
          rocks_ ? static_cast<float>(double(passages_[c]) / double(rocks_)) : 0.0f;
  }
  if (request_.tree_hits) {
    out.push_back(layer(ToString(RasterKind::kTreeHits), "count", "count",
                        "tree hits, impacts of rocks on the stems standing in the cell", 0));
    std::copy(tree_hits_.begin(), tree_hits_.end(), out.back().values.begin());
    out.back().counts.assign(tree_hits_.begin(), tree_hits_.end());
  }
  // No value where the DEM has none.
  for (std::size_t c = 0; c < cells; ++c)
    if (std::isnan(dem.z_m[c]))
      for (RasterLayer& l : out) {
        l.values[c] = RasterLayer::kNoData;
        if (!l.counts.empty()) l.counts[c] = static_cast<std::int32_t>(RasterLayer::kNoData);
      }
  return out;
}

std::size_t RasterAccumulator::MemoryBytes() const {
  return sizeof(int) * (passages_.capacity() + deposits_.capacity() + tree_hits_.capacity() +
                        slot_.capacity()) +
         sizeof(ValueSummary) * summaries_.capacity() + (spill_ ? spill_->MemoryBytes() : 0);
}

namespace {

// Format of RasterAccumulator::Serialize; a change of layout changes the number.
constexpr std::uint32_t kStateFormat = 4;

std::string PercentileList(const std::vector<std::int32_t>& percentiles) {
  std::string text;
  for (std::int32_t p : percentiles)
    text.append(text.empty() ? "p" : ", p").append(std::to_string(p));
  return text.empty() ? "none" : text;
}

// Bit k: the raster of kind k (RasterKind's order) is requested.
std::uint32_t RequestBits(const RasterRequest& r) {
  std::uint32_t bits = 0;
  for (int k = 0; k < kRasterKindNames.size(); ++k)
    bits |= std::uint32_t(r.Wants(static_cast<RasterKind>(k))) << k;
  return bits;
}

// The cells with a non-zero count, and their counts.
void PutCounts(ByteWriter& out, const std::vector<int>& counts) {
  std::vector<std::int32_t> cells, values;
  for (std::size_t c = 0; c < counts.size(); ++c)
    if (counts[c] != 0) {
      cells.push_back(static_cast<std::int32_t>(c));
      values.push_back(counts[c]);
    }
  out.PutVector(cells);
  out.PutVector(values);
}

void GetCounts(ByteReader& in, std::vector<int>& counts) {
  const auto cells = in.GetVector<std::int32_t>();
  const auto values = in.GetVector<std::int32_t>();
  if (cells.size() != values.size()) in.Fail();
  for (std::size_t k = 0; k < cells.size(); ++k) {
    if (cells[k] < 0 || static_cast<std::size_t>(cells[k]) >= counts.size()) in.Fail();
    counts[static_cast<std::size_t>(cells[k])] = values[k];
  }
}

}  // namespace

void RasterAccumulator::Serialize(ByteWriter& out) const {
  out.Put(kStateFormat);
  out.Put(RequestBits(request_));
  out.PutVector(
      std::vector<std::int32_t>(request_.percentiles.begin(), request_.percentiles.end()));
  out.Put(request_.grid);
  out.Put<std::int64_t>(rocks_);
  PutCounts(out, passages_);
  PutCounts(out, deposits_);
  PutCounts(out, tree_hits_);
  std::vector<std::int32_t> passed;  // in cell order, so that the bytes do not depend on the order
  for (std::size_t c = 0; c < slot_.size(); ++c)
    if (slot_[c] >= 0) passed.push_back(static_cast<std::int32_t>(c));
  out.PutVector(passed);
  for (std::int32_t c : passed)
    for (int k = 0; k < quantities(); ++k)
      summaries_[static_cast<std::size_t>(slot_[static_cast<std::size_t>(c)]) +
                 static_cast<std::size_t>(k)]
          .Serialize(out);
  // The records WriteSpill writes, per band.
  std::vector<std::int64_t> records;
  for (int b = 0; spill_ && b < spill_->bands(); ++b) records.push_back(spill_->records(b));
  out.PutVector(records);
}

void RasterAccumulator::WriteSpill(std::ostream& spill) const {
  if (spill_) spill_->WriteBands(spill);
}

void RasterAccumulator::MergeSerialized(ByteReader& in, std::istream& spill) {
  const RasterRequest& request = request_;
  if (in.Get<std::uint32_t>() != kStateFormat) in.Fail("was written by another version of talus");
  if (in.Get<std::uint32_t>() != RequestBits(request))
    in.Fail("holds other rasters than the scene asks for");
  const auto percentiles = in.GetVector<std::int32_t>();
  const std::vector<std::int32_t> wanted(request.percentiles.begin(), request.percentiles.end());
  if (percentiles != wanted)
    in.Fail("holds other percentiles (" + PercentileList(percentiles) +
            ") than the scene asks for (" + PercentileList(wanted) + ")");
  const auto grid = in.Get<GridGeometry>();
  if (grid.nx != request.grid.nx || grid.ny != request.grid.ny || grid.x0_m != request.grid.x0_m ||
      grid.y0_m != request.grid.y0_m || grid.dx_m != request.grid.dx_m ||
      grid.dy_m != request.grid.dy_m)
    in.Fail("is on another grid than the scene's DEM");
  const auto rocks = in.Get<std::int64_t>();
  if (rocks < 0) in.Fail();
  rocks_ += static_cast<long>(rocks);
  std::vector<int> passages(static_cast<std::size_t>(grid.nx) * grid.ny, 0);
  std::vector<int> deposits(passages.size(), 0), tree_hits(passages.size(), 0);
  GetCounts(in, passages);
  GetCounts(in, deposits);
  GetCounts(in, tree_hits);
  for (std::size_t c = 0; c < passages_.size(); ++c) passages_[c] += passages[c];
  for (std::size_t c = 0; c < deposits_.size(); ++c) deposits_[c] += deposits[c];
  for (std::size_t c = 0; c < tree_hits_.size(); ++c) tree_hits_[c] += tree_hits[c];
  const auto passed = in.GetVector<std::int32_t>();
  if (!passed.empty() && slot_.empty()) in.Fail();
  for (std::size_t k = 0; k < passed.size(); ++k) {
    const std::int32_t c = passed[k];
    if (c < 0 || static_cast<std::size_t>(c) >= slot_.size() || (k > 0 && c <= passed[k - 1]))
      in.Fail();
    ValueSummary* s = Summaries(c);
    for (int q = 0; q < quantities(); ++q) s[q].Merge(ValueSummary::Deserialize(in));
  }
  const auto records = in.GetVector<std::int64_t>();
  if (!spill_) {
    if (!records.empty()) in.Fail();
    return;
  }
  if (const std::string wrong = spill_->ReadBands(spill, records); !wrong.empty())
    in.Fail("is truncated or damaged: its spilled values (" + wrong + ")");
}

}  // namespace talus::ensemble
