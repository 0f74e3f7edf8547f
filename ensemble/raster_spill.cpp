#include "ensemble/raster_spill.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <istream>
#include <ostream>
#include <stdexcept>

namespace talus::ensemble {

namespace fs = std::filesystem;

// A range of cells [first, end) and the records it holds.
struct RasterSpill::Range {
  int first = 0, end = 0;
  std::int64_t records = 0;
};

namespace {

constexpr std::size_t kReadBytes = std::size_t{1} << 20;  // records read at a time
constexpr std::size_t kSplitBufferBytes = std::size_t{16} << 10;
constexpr int kMaxSplit = 64;  // files a range is split into at a time

std::uint32_t BitsOf(float v) {
  std::uint32_t bits;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

float FloatOf(std::uint32_t bits) {
  float v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// A float's bits as an unsigned key in the floats' order (negatives reversed below positives).
std::uint32_t KeyOf(float v) {
  const std::uint32_t bits = BitsOf(v);
  return (bits & 0x80000000u) ? ~bits : bits | 0x80000000u;
}

float FloatOfKey(std::uint32_t key) {
  return FloatOf((key & 0x80000000u) ? key & 0x7fffffffu : ~key);
}

// The rank (1-based) of the nearest-rank `percent`-th percentile of n values, in integers.
std::int64_t RankOf(int percent, std::int64_t n) {
  return (static_cast<std::int64_t>(percent) * n + 99) / 100;
}

std::runtime_error WriteError(const std::string& path) {
  return std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
}

void AppendToFile(const std::string& path, const char* data, std::size_t bytes) {
  if (bytes == 0) return;
  std::FILE* out = std::fopen(path.c_str(), "ab");
  if (!out) throw WriteError(path);
  const bool written = std::fwrite(data, 1, bytes, out) == bytes;
  if (std::fclose(out) != 0 || !written) throw WriteError(path);
}

// Calls each(record) for every record of the file at `path` (record_bytes each), read in chunks.
template <class Each>
void ForEachRecord(const std::string& path, std::size_t record_bytes, Each each) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    if (!fs::exists(path)) return;  // no record was ever written there
    throw std::runtime_error("cannot read " + path);
  }
  std::vector<char> chunk(kReadBytes / record_bytes * record_bytes);
  while (in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0) {
    const auto n = static_cast<std::size_t>(in.gcount());
    if (n % record_bytes != 0) throw std::runtime_error(path + " ends within a record");
    for (std::size_t at = 0; at < n; at += record_bytes) each(chunk.data() + at);
  }
  if (in.bad()) throw std::runtime_error("cannot read " + path);
}

int CellOfRecord(const char* record) {
  std::int32_t cell;
  std::memcpy(&cell, record, sizeof cell);
  return cell;
}

float ValueOfRecord(const char* record, int v) {
  float value;
  std::memcpy(&value, record + 4 + 4 * static_cast<std::size_t>(v), sizeof value);
  return value;
}

}  // namespace

RasterSpill::RasterSpill(const GridGeometry& grid, int values, RasterSpillOptions options)
    : grid_(grid), values_(values), options_(std::move(options)) {
  const int bands = std::clamp(grid.ny, 1, kMaxBands);
  rows_per_band_ = std::max(1, (grid.ny + bands - 1) / bands);
  const int used = std::max(1, (grid.ny + rows_per_band_ - 1) / rows_per_band_);
  records_.assign(static_cast<std::size_t>(used), 0);
  buffers_.resize(static_cast<std::size_t>(used));
}

RasterSpill::RasterSpill(RasterSpill&& other) noexcept
    : grid_(other.grid_),
      values_(other.values_),
      rows_per_band_(other.rows_per_band_),
      options_(std::move(other.options_)),
      created_(other.created_),
      records_(std::move(other.records_)),
      buffers_(std::move(other.buffers_)) {
  other.created_ = false;
}

RasterSpill& RasterSpill::operator=(RasterSpill&& other) noexcept {
  if (this == &other) return *this;
  if (created_) {
    std::error_code ignored;
    fs::remove_all(options_.dir, ignored);
  }
  grid_ = other.grid_;
  values_ = other.values_;
  rows_per_band_ = other.rows_per_band_;
  options_ = std::move(other.options_);
  created_ = other.created_;
  records_ = std::move(other.records_);
  buffers_ = std::move(other.buffers_);
  other.created_ = false;
  return *this;
}

RasterSpill::~RasterSpill() {
  if (!created_) return;
  std::error_code ignored;
  fs::remove_all(options_.dir, ignored);
}

const std::string& RasterSpill::Directory() {
  if (created_) return options_.dir;
  if (options_.dir.empty()) {
    std::string pattern = (fs::temp_directory_path() / "talus-raster-spill-XXXXXX").string();
    if (!::mkdtemp(pattern.data()))
      throw std::runtime_error("cannot create " + pattern + ": " + std::strerror(errno));
    options_.dir = pattern;
  } else {
    std::error_code error;
    if (!fs::create_directory(options_.dir, error) || error)
      throw std::runtime_error("cannot create " + options_.dir + ": " +
                               (error ? error.message() : std::string("it exists")));
  }
  created_ = true;
  return options_.dir;
}

std::string RasterSpill::BandPath(int band) const {
  char name[32];
  std::snprintf(name, sizeof name, "band-%03d.bin", band);
  return (fs::path(options_.dir) / name).string();
}

void RasterSpill::Flush(int band) {
  std::vector<char>& buffer = buffers_[static_cast<std::size_t>(band)];
  if (buffer.empty()) return;
  Directory();
  AppendToFile(BandPath(band), buffer.data(), buffer.size());
  buffer.clear();
}

void RasterSpill::Append(int cell, const float* values) {
  const int band = BandOf(cell);
  std::vector<char>& buffer = buffers_[static_cast<std::size_t>(band)];
  if (buffer.capacity() == 0) buffer.reserve(kBufferBytes);
  const auto at = buffer.size();
  buffer.resize(at + record_bytes());
  const auto cell32 = static_cast<std::int32_t>(cell);
  std::memcpy(buffer.data() + at, &cell32, sizeof cell32);
  for (int v = 0; v < values_; ++v) {
    const float value = values[v] == 0.0f ? 0.0f : values[v];  // -0 as +0
    std::memcpy(buffer.data() + at + 4 + 4 * static_cast<std::size_t>(v), &value, sizeof value);
  }
  ++records_[static_cast<std::size_t>(band)];
  if (buffer.size() + record_bytes() > kBufferBytes) Flush(band);
}

void RasterSpill::Append(const RasterSpill& other) {
  for (int b = 0; b < bands(); ++b) {
    Flush(b);
    const std::size_t k = static_cast<std::size_t>(b);
    if (other.records_[k] == 0) continue;
    if (other.created_)
      ForEachRecord(other.BandPath(b), record_bytes(), [&](const char* record) {
        std::vector<char>& buffer = buffers_[k];
        buffer.insert(buffer.end(), record, record + record_bytes());
        if (buffer.size() + record_bytes() > kBufferBytes) Flush(b);
      });
    const std::vector<char>& pending = other.buffers_[k];
    buffers_[k].insert(buffers_[k].end(), pending.begin(), pending.end());
    Flush(b);
    records_[k] += other.records_[k];
  }
}

std::size_t RasterSpill::MemoryBytes() const {
  std::size_t bytes = records_.capacity() * sizeof(std::int64_t);
  for (const std::vector<char>& b : buffers_) bytes += b.capacity();
  return bytes;
}

std::uint64_t RasterSpill::DiskBytes() const {
  std::uint64_t records = 0;
  for (std::int64_t r : records_) records += static_cast<std::uint64_t>(r);
  return records * record_bytes();
}

void RasterSpill::WriteBands(std::ostream& out) const {
  for (int b = 0; b < bands(); ++b) {
    const std::size_t k = static_cast<std::size_t>(b);
    if (created_) {
      std::ifstream in(BandPath(b), std::ios::binary);
      if (in) {
        std::vector<char> chunk(kReadBytes);
        while (in.read(chunk.data(), static_cast<std::streamsize>(chunk.size())) || in.gcount() > 0)
          out.write(chunk.data(), in.gcount());
        if (in.bad()) throw std::runtime_error("cannot read " + BandPath(b));
      }
    }
    out.write(buffers_[k].data(), static_cast<std::streamsize>(buffers_[k].size()));
  }
  if (!out) throw std::runtime_error("cannot write the raster spill");
}

std::string RasterSpill::ReadBands(std::istream& in, const std::vector<std::int64_t>& records) {
  if (records.size() != records_.size()) return "another number of bands";
  std::vector<char> chunk(kReadBytes / record_bytes() * record_bytes());
  for (int b = 0; b < bands(); ++b) {
    const std::size_t k = static_cast<std::size_t>(b);
    if (records[k] < 0) return "a negative count";
    Flush(b);
    for (std::int64_t left = records[k]; left > 0;) {
      const auto n = static_cast<std::size_t>(
          std::min<std::int64_t>(left, static_cast<std::int64_t>(chunk.size() / record_bytes())));
      if (!in.read(chunk.data(), static_cast<std::streamsize>(n * record_bytes())))
        return "they end early";
      for (std::size_t r = 0; r < n; ++r) {
        const int cell = CellOfRecord(chunk.data() + r * record_bytes());
        if (cell < 0 || cell >= grid_.nx * grid_.ny || BandOf(cell) != b)
          return "a value of cell " + std::to_string(cell) + " in band " + std::to_string(b);
      }
      Directory();
      AppendToFile(BandPath(b), chunk.data(), n * record_bytes());
      records_[k] += static_cast<std::int64_t>(n);
      left -= static_cast<std::int64_t>(n);
    }
  }
  return "";
}

void RasterSpill::Percentiles(const std::vector<int>& passages, const std::vector<int>& percents,
                              std::vector<std::vector<float>>& out) {
  if (percents.empty()) return;
  for (int b = 0; b < bands(); ++b) {
    Flush(b);
    const std::size_t k = static_cast<std::size_t>(b);
    Range range;
    range.first = b * rows_per_band_ * grid_.nx;
    range.end = std::min(grid_.ny, (b + 1) * rows_per_band_) * grid_.nx;
    for (int c = range.first; c < range.end; ++c)
      range.records += passages[static_cast<std::size_t>(c)];
    if (range.records != records_[k])
      throw std::runtime_error("the raster spill's band " + std::to_string(b) + " holds " +
                               std::to_string(records_[k]) + " records, its cells' passages " +
                               std::to_string(range.records));
    if (range.records == 0) continue;
    Select(BandPath(b), range, passages, percents, out, 0);
  }
}

void RasterSpill::Select(const std::string& path, const Range& range,
                         const std::vector<int>& passages, const std::vector<int>& percents,
                         std::vector<std::vector<float>>& out, int depth) {
  const std::size_t value_bytes = 4 * static_cast<std::size_t>(values_);
  const std::int64_t fits =
      std::max<std::int64_t>(1, static_cast<std::int64_t>(options_.memory_bytes / value_bytes));
  if (range.records <= fits) return SelectInMemory(path, range, passages, percents, out);
  int passed = 0, last = -1;
  for (int c = range.first; c < range.end && passed < 2; ++c)
    if (passages[static_cast<std::size_t>(c)] > 0) ++passed, last = c;
  if (passed == 1) return SelectByRadix(path, last, percents, out);

  // Split into groups of neighbouring cells of at most `target` records each (or one cell alone):
  // every two neighbouring groups hold more than `target`, so there are at most 2 kMaxSplit + 1.
  const std::int64_t target = std::max(fits, (range.records + kMaxSplit - 1) / kMaxSplit);
  std::vector<Range> groups;
  for (int c = range.first; c < range.end; ++c) {
    const int n = passages[static_cast<std::size_t>(c)];
    if (groups.empty() || (groups.back().records > 0 && groups.back().records + n > target))
      groups.push_back({c, c, 0});
    groups.back().end = c + 1;
    groups.back().records += n;
  }
  std::vector<int> group_of(static_cast<std::size_t>(range.end - range.first));
  for (std::size_t g = 0; g < groups.size(); ++g)
    for (int c = groups[g].first; c < groups[g].end; ++c)
      group_of[static_cast<std::size_t>(c - range.first)] = static_cast<int>(g);
  std::vector<std::string> paths;
  for (std::size_t g = 0; g < groups.size(); ++g)
    paths.push_back(path + "." + std::to_string(depth) + "-" + std::to_string(g));
  {
    std::vector<std::vector<char>> buffers(groups.size());
    ForEachRecord(path, record_bytes(), [&](const char* record) {
      const int cell = CellOfRecord(record);
      if (cell < range.first || cell >= range.end)
        throw std::runtime_error(path + " holds a record of cell " + std::to_string(cell) +
                                 " outside its cells");
      const auto g =
          static_cast<std::size_t>(group_of[static_cast<std::size_t>(cell - range.first)]);
      buffers[g].insert(buffers[g].end(), record, record + record_bytes());
      if (buffers[g].size() >= kSplitBufferBytes) {
        AppendToFile(paths[g], buffers[g].data(), buffers[g].size());
        buffers[g].clear();
      }
    });
    for (std::size_t g = 0; g < groups.size(); ++g)
      AppendToFile(paths[g], buffers[g].data(), buffers[g].size());
  }
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (groups[g].records > 0) Select(paths[g], groups[g], passages, percents, out, depth + 1);
    std::error_code ignored;
    fs::remove(paths[g], ignored);
  }
}

void RasterSpill::SelectInMemory(const std::string& path, const Range& range,
                                 const std::vector<int>& passages, const std::vector<int>& percents,
                                 std::vector<std::vector<float>>& out) {
  // Counting sort by cell: cell c's values of quantity v at values[v records + offset[c] ...].
  const auto cells = static_cast<std::size_t>(range.end - range.first);
  std::vector<std::int64_t> offset(cells + 1, 0), next(cells);
  for (std::size_t c = 0; c < cells; ++c)
    offset[c + 1] = offset[c] + passages[static_cast<std::size_t>(range.first) + c];
  std::copy(offset.begin(), offset.end() - 1, next.begin());
  const auto records = static_cast<std::size_t>(range.records);
  std::vector<float> values(records * static_cast<std::size_t>(values_));
  ForEachRecord(path, record_bytes(), [&](const char* record) {
    const int cell = CellOfRecord(record);
    const auto c = static_cast<std::size_t>(cell - range.first);
    if (cell < range.first || cell >= range.end || next[c] == offset[c + 1])
      throw std::runtime_error(path + " holds more records of cell " + std::to_string(cell) +
                               " than passed it");
    const auto at = static_cast<std::size_t>(next[c]++);
    for (int v = 0; v < values_; ++v)
      values[static_cast<std::size_t>(v) * records + at] = ValueOfRecord(record, v);
  });
  for (std::size_t c = 0; c < cells; ++c)
    if (next[c] != offset[c + 1])
      throw std::runtime_error(path + " holds fewer records of cell " +
                               std::to_string(range.first + static_cast<int>(c)) +
                               " than passed it");
  for (std::size_t c = 0; c < cells; ++c) {
    if (offset[c + 1] == offset[c]) continue;
    for (int v = 0; v < values_; ++v) {
      float* first = values.data() + static_cast<std::size_t>(v) * records + offset[c];
      float* last = values.data() + static_cast<std::size_t>(v) * records + offset[c + 1];
      last = std::partition(first, last, [](float x) { return std::isfinite(x); });
      const std::int64_t n = last - first;
      if (n == 0) continue;
      // Ascending percentiles: each rank is at or after the one before, and nth_element leaves
      // nothing smaller after it.
      float* from = first;
      for (std::size_t k = 0; k < percents.size(); ++k) {
        float* nth = first + (RankOf(percents[k], n) - 1);
        std::nth_element(from, nth, last);
        out[static_cast<std::size_t>(v) * percents.size() + k]
           [static_cast<std::size_t>(range.first) + c] = *nth;
        from = nth;
      }
    }
  }
}

void RasterSpill::SelectByRadix(const std::string& path, int cell, const std::vector<int>& percents,
                                std::vector<std::vector<float>>& out) {
  // Two passes per percentile over the cell's records: the key's high 16 bits, then its low 16
  // bits among the values with those high bits.
  std::vector<std::int64_t> histogram(std::size_t{1} << 16);
  for (int v = 0; v < values_; ++v) {
    std::fill(histogram.begin(), histogram.end(), 0);
    std::int64_t n = 0;
    ForEachRecord(path, record_bytes(), [&](const char* record) {
      const float x = ValueOfRecord(record, v);
      if (CellOfRecord(record) != cell || !std::isfinite(x)) return;
      ++histogram[KeyOf(x) >> 16];
      ++n;
    });
    if (n == 0) continue;
    std::vector<std::int64_t> low(std::size_t{1} << 16);
    for (std::size_t k = 0; k < percents.size(); ++k) {
      std::int64_t rank = RankOf(percents[k], n);
      std::uint32_t high = 0;
      while (rank > histogram[high]) rank -= histogram[high++];
      std::fill(low.begin(), low.end(), 0);
      ForEachRecord(path, record_bytes(), [&](const char* record) {
        const float x = ValueOfRecord(record, v);
        if (CellOfRecord(record) != cell || !std::isfinite(x)) return;
        const std::uint32_t key = KeyOf(x);
        if ((key >> 16) == high) ++low[key & 0xffffu];
      });
      std::uint32_t bits = 0;
      while (rank > low[bits]) rank -= low[bits++];
      out[static_cast<std::size_t>(v) * percents.size() + k][static_cast<std::size_t>(cell)] =
          FloatOfKey((high << 16) | bits);
    }
  }
}

}  // namespace talus::ensemble
