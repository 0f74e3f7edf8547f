#pragma once
// Raster statistics of an ensemble on the DEM grid: each rock leaves a footprint (the cells its
// centre of mass passed, with its largest speed, energy and jump height in each), and footprints
// are summarised per cell so that the rasters do not depend on the number of threads, ranks or
// partial runs.

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "common/bytes.hpp"
#include "ensemble/cell_summary.hpp"
#include "ensemble/outcome.hpp"
#include "ensemble/raster_spill.hpp"
#include "ensemble/recorders.hpp"
#include "solver/option_table.hpp"
#include "solver/simulate.hpp"
#include "solver/terrain.hpp"

namespace talus::ensemble {

// The rasters a scene's [output] rasters may name, in the order of RasterRequest's flags. The first
// three are statistics rasters (<name>_max, _mean, _p<NN>), the others one raster each.
enum class RasterKind {
  kSpeed,
  kEnergy,
  kJumpHeight,
  kPassages,
  kDeposits,
  kReachProbability,
  kTreeHits
};
// "speed", "energy", "jump_height", "passages", "deposits", "reach_probability", "tree_hits": the
// scene's
// [output] rasters, summary.json's raster_output and the rasters' file names read this one list.
extern const EnumNames kRasterKindNames;
const char* ToString(RasterKind kind);

// Which rasters to accumulate; nothing requested means no raster work at all. Cells are those of
// `grid`: node (i, j) is the centre of cell (i, j), as for the DEM.
struct RasterRequest {
  GridGeometry grid;
  bool speed = false;   // speed_max, speed_mean, speed_p<NN> (m/s)
  bool energy = false;  // energy_max, energy_mean, energy_p<NN> (J, translational + rotational)
  bool jump_height =
      false;  // jump_height_max, _mean, _p<NN> (m, centre of mass above ground along the normal)
  bool passages = false;           // rocks that passed the cell
  bool deposits = false;           // rocks that came to rest in the cell
  bool reach_probability = false;  // fraction of all rocks that passed the cell
  bool tree_hits = false;          // impacts on the stems of the cell (scenes with a [forest])
  // The percentiles (percent, ascending, each 1 .. 99) of the *_p<NN> rasters of speed, energy
  // and jump height.
  std::vector<int> percentiles = {95};

  // The flag of `kind`.
  bool& Wants(RasterKind kind);
  bool Wants(RasterKind kind) const;

  bool any() const {
    return speed || energy || jump_height || passages || deposits || reach_probability || tree_hits;
  }
  bool needs_passes() const {
    return speed || energy || jump_height || passages || reach_probability;
  }
  // False, with "percentiles = ... <reason>" in *why, when the percentiles are not ascending
  // integers in 1 .. 99.
  bool IsValid(std::string* why) const;
};

// Records one rock's footprint (outcome.footprint) from the solver's steps. One per thread,
// reused across rocks.
class FootprintRecorder : public RockRecorder {
 public:
  FootprintRecorder(const RasterRequest& request, const Terrain& terrain);
  void Begin(const RockOutcome& outcome) override;
  void OnStep(const RockState& state, const StepReport& step, const TerrainSample& ground) override;
  void Finish(RockOutcome& outcome) override;

 private:
  void Mark(const Eigen::Vector3d& position, float speed, float energy, float jump);
  int CellOf(double x_m, double y_m) const;

  const RasterRequest& request_;
  const Terrain& terrain_;
  const RockShape* rock_ = nullptr;
  std::vector<int> slot_;  // per cell: index into footprint_ or -1
  Footprint footprint_;
  Eigen::Vector3d previous_ = Eigen::Vector3d::Zero();
};

// One output raster: values in grid order (row j after row j - 1, j increasing with y). Every
// raster is kNoData where the DEM has nodata; the statistics also where no rock passed.
struct RasterLayer {
  std::string name;  // e.g. "speed_p95"; the file is <name>.tif
  std::string unit;  // "m/s", "J", "m", "count", "1"
  std::vector<float> values;
  std::string quantity = {};   // speed, energy, jump_height, passages, deposits, reach_probability
  std::string statistic = {};  // max, mean, p<NN>, count (passages, deposits), fraction (reach)
  std::string description = {};  // e.g. "energy, 95th percentile over passing rocks"
  // The counts of a count layer (passages, deposits) exactly, kNoData where the DEM has no height;
  // empty for the others. `values` holds them too, as float (exact up to 2^24).
  std::vector<std::int32_t> counts = {};
  static constexpr float kNoData = -9999.0f;
};

// Merges footprints into per-cell summaries (cell_summary.hpp) and spills the values behind the
// percentiles to disk (raster_spill.hpp): counts, maxima, means and percentiles whose result does
// not depend on the order of the rocks or on how they were split between accumulators (Merge), to
// the bit; the percentiles are exact. Memory: 4 bytes per cell for each of the slot, passage and
// deposit grids in use, per passed cell and requested quantity one ValueSummary (32 bytes), and
// the spill's write buffers; none of it grows with the number of rocks. Disk: 4 + 4 q bytes per
// cell passage (q: the quantities requested) when percentiles are asked for.
class RasterAccumulator {
 public:
  explicit RasterAccumulator(const RasterRequest& request, RasterSpillOptions spill = {});
  void Add(const Footprint& footprint);
  // Adds the rocks of `other`, which must have the same request (its spilled values are copied).
  void Merge(const RasterAccumulator& other);
  // The rasters, in the order speed, energy, jump height (each max, mean, then the percentiles
  // ascending), passages, deposits, reach probability, tree hits; `dem` is the DEM on the request's
  // grid, whose nodata cells (NaN) are nodata in every raster. Reads the spill back (in at most
  // RasterSpillOptions::memory_bytes of values at a time).
  std::vector<RasterLayer> Finish(const Heightfield& dem);
  long rocks() const { return rocks_; }
  const RasterRequest& request() const { return request_; }
  // Bytes held now (grids, summaries, the spill's buffers), for memory reports, and bytes spilled.
  std::size_t MemoryBytes() const;
  std::uint64_t SpillBytes() const { return spill_ ? spill_->DiskBytes() : 0; }

  // The state, for merging in another process: Serialize writes the counts and summaries,
  // WriteSpill the spilled values (raster_spill.hpp; none when no percentile is asked for).
  // MergeSerialized adds such a state (Serialize's bytes from `in`, WriteSpill's from `spill`) to
  // this accumulator; it checks that it was made for the same request (rasters and percentiles)
  // and grid, and throws std::runtime_error (naming `in`) otherwise or when the bytes are damaged.
  void Serialize(ByteWriter& out) const;
  void WriteSpill(std::ostream& spill) const;
  void MergeSerialized(ByteReader& in, std::istream& spill);

 private:
  // The summaries of a passed cell, created on its first passage.
  ValueSummary* Summaries(int cell);
  int quantities() const;

  RasterRequest request_;
  long rocks_ = 0;
  std::vector<int> passages_, deposits_, tree_hits_;  // passages_ also for the spill's counts
  std::vector<int> slot_;  // per cell: index of its first summary in summaries_, or -1
  std::vector<ValueSummary> summaries_;  // per passed cell: speed, energy, jump height as requested
  std::optional<RasterSpill> spill_;     // with a quantity and a percentile requested
};

}  // namespace talus::ensemble
