#pragma once
// The values behind the percentile rasters, on disk: one fixed-size record per cell passage (the
// cell, then the float value of each quantity the rasters ask for), appended in the order the
// rocks are merged to one file per band of grid rows, in a directory of its own. Memory: a write
// buffer per band (kBufferBytes) however many rocks pass; disk: 4 + 4 q bytes per passage.
// Percentiles() takes every cell's nearest-rank percentiles exactly, within a fixed memory
// budget: a band's records are grouped by cell (a counting sort on the exact per-cell counts)
// and each percentile picked with std::nth_element; a band whose values exceed the budget is
// split by cell ranges into smaller files first, and a single cell that alone exceeds it is
// selected in radix passes over its file (16 bits at a time). The value picked depends only on
// the multiset of a cell's values, never on the order of the records, so the rasters are the
// same bits for any number of threads, parts or ranks.

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

#include "solver/terrain.hpp"

namespace talus::ensemble {

struct RasterSpillOptions {
  // The directory to create for the band files (its parent must exist; it must not), e.g. inside
  // a run's staging directory; empty: a new directory under the system's temporary directory.
  // Removed with the spill.
  std::string dir;
  // Memory for the values of one group of cells at Percentiles() (bytes, > 0). Percentiles()
  // holds about twice this at most; 4 MiB took 1.75 s against 1.17 s with 16 MiB for the 33
  // million records of 10^5 tirol rocks, and kept 18 MB less.
  std::size_t memory_bytes = std::size_t{4} << 20;
};

class RasterSpill {
 public:
  static constexpr int kMaxBands = 64;
  static constexpr std::size_t kBufferBytes = std::size_t{32} << 10;  // per band

  // Records of `values` floats (>= 1) per passage on `grid`. Creates no file before the first
  // record.
  RasterSpill(const GridGeometry& grid, int values, RasterSpillOptions options);
  ~RasterSpill();  // removes the directory and everything in it
  RasterSpill(RasterSpill&& other) noexcept;
  RasterSpill& operator=(RasterSpill&& other) noexcept;
  RasterSpill(const RasterSpill&) = delete;
  RasterSpill& operator=(const RasterSpill&) = delete;

  // One passage of `cell` (0 .. nx ny - 1) with values[0 .. values - 1]; -0 is stored as +0.
  // Throws std::runtime_error when a band file cannot be written.
  void Append(int cell, const float* values);
  // Appends the records of `other` (same grid and values) after this spill's, band by band.
  void Append(const RasterSpill& other);

  int bands() const { return static_cast<int>(records_.size()); }
  int values() const { return values_; }
  std::size_t record_bytes() const { return 4 + 4 * static_cast<std::size_t>(values_); }
  std::int64_t records(int band) const { return records_[static_cast<std::size_t>(band)]; }
  // The band of a cell: its row's.
  int BandOf(int cell) const { return cell / grid_.nx / rows_per_band_; }
  // Bytes held in memory (the write buffers) and on disk (the records).
  std::size_t MemoryBytes() const;
  std::uint64_t DiskBytes() const;

  // Writes every band's records, band after band (records(b) each), to `out`; ReadBands reads
  // such a stream (of a spill on the same grid with the same values, `records` per band) into this
  // one's bands, after its records, and returns what is wrong with it ("" when all was read:
  // it ends early, a record's cell is not in its band). Throw std::runtime_error when a file
  // cannot be read or written.
  void WriteBands(std::ostream& out) const;
  std::string ReadBands(std::istream& in, const std::vector<std::int64_t>& records);

  // The nearest-rank percentiles (rank ceil(p n / 100) of a cell's n finite values, in integers)
  // of every cell and value: out[v * percents.size() + k][cell] for value v and percents[k]
  // (ascending, 1 .. 100), set where the cell has a finite value and left as it is elsewhere.
  // `passages[cell]` is the number of records of each cell. Throws std::runtime_error when the
  // files do not hold those records.
  void Percentiles(const std::vector<int>& passages, const std::vector<int>& percents,
                   std::vector<std::vector<float>>& out);

 private:
  struct Range;
  void Flush(int band);
  const std::string& Directory();
  std::string BandPath(int band) const;
  void Select(const std::string& path, const Range& range, const std::vector<int>& passages,
              const std::vector<int>& percents, std::vector<std::vector<float>>& out, int depth);
  void SelectInMemory(const std::string& path, const Range& range, const std::vector<int>& passages,
                      const std::vector<int>& percents, std::vector<std::vector<float>>& out);
  void SelectByRadix(const std::string& path, int cell, const std::vector<int>& percents,
                     std::vector<std::vector<float>>& out);

  GridGeometry grid_;
  int values_;
  int rows_per_band_;
  RasterSpillOptions options_;
  bool created_ = false;                    // the directory exists and is this spill's to remove
  std::vector<std::int64_t> records_;       // per band, buffered ones included
  std::vector<std::vector<char>> buffers_;  // per band, records not yet written
};

}  // namespace talus::ensemble
