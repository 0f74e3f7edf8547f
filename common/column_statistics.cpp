#include "common/column_statistics.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <stdexcept>

#include "common/statistics.hpp"

namespace talus {
namespace {

constexpr int kDigitBits = 12;
constexpr std::size_t kBins = std::size_t{1} << kDigitBits;
constexpr std::size_t kHistogramBytes = kBins * sizeof(std::uint64_t);

// The finite double's bit pattern as an unsigned integer of the same order (-0 as +0).
std::uint64_t OrderedKey(double v) {
  const auto bits = std::bit_cast<std::uint64_t>(v == 0 ? 0.0 : v);
  return (bits >> 63) != 0 ? ~bits : bits | (std::uint64_t{1} << 63);
}

double FromOrderedKey(std::uint64_t key) {
  return std::bit_cast<double>((key >> 63) != 0 ? key & ~(std::uint64_t{1} << 63) : ~key);
}

// One percentile being narrowed: the `rank`-th smallest (1-based) of the column's finite values
// whose key starts with the `bits` bits of `prefix`, of which there are `candidates`.
struct Target {
  std::size_t column = 0, slot = 0;
  std::uint64_t rank = 0, prefix = 0, candidates = 0;
  int bits = 0;
  bool done = false;
};

bool Matches(const Target& t, std::uint64_t key) {
  return t.bits == 0 || (key >> (64 - t.bits)) == t.prefix;
}

// Reads the source once for a batch of targets: a histogram of the next digit of each target's
// candidates, or the candidates themselves when `collect`; then narrows or resolves each target.
void NarrowBatch(const ColumnSource& source, std::vector<Target*>& batch,
                 const std::vector<bool>& collect, std::vector<ColumnStatistics>& out) {
  std::vector<std::vector<std::size_t>> of_column(out.size());
  for (std::size_t b = 0; b < batch.size(); ++b) of_column[batch[b]->column].push_back(b);
  std::vector<std::vector<std::uint64_t>> histogram(batch.size());
  std::vector<std::vector<double>> values(batch.size());
  for (std::size_t b = 0; b < batch.size(); ++b) {
    if (collect[b]) {
      values[b].reserve(batch[b]->candidates);
    } else {
      histogram[b].assign(kBins, 0);
    }
  }
  source([&](std::size_t column, double v) {
    if (column >= of_column.size() || !std::isfinite(v)) return;
    const std::uint64_t key = OrderedKey(v);
    for (std::size_t b : of_column[column]) {
      const Target& t = *batch[b];
      if (!Matches(t, key)) continue;
      if (collect[b]) {
        values[b].push_back(v == 0 ? 0.0 : v);
      } else {
        const int width = std::min(kDigitBits, 64 - t.bits);
        ++histogram[b][(key << t.bits) >> (64 - width)];
      }
    }
  });
  for (std::size_t b = 0; b < batch.size(); ++b) {
    Target& t = *batch[b];
    const std::uint64_t found =
        collect[b] ? values[b].size()
                   : std::accumulate(histogram[b].begin(), histogram[b].end(), std::uint64_t{0});
    if (found != t.candidates)
      throw std::runtime_error("a file read again for its statistics changed in between");
    if (collect[b]) {
      std::vector<double>& v = values[b];
      std::nth_element(v.begin(), v.begin() + static_cast<long>(t.rank - 1), v.end());
      out[t.column].percentiles[t.slot] = v[t.rank - 1];
      t.done = true;
      continue;
    }
    const int width = std::min(kDigitBits, 64 - t.bits);
    std::uint64_t below = 0, bin = 0;
    while (below + histogram[b][bin] < t.rank) below += histogram[b][bin++];
    t.prefix = (t.prefix << width) | bin;
    t.bits += width;
    t.rank -= below;
    t.candidates = histogram[b][bin];
    if (t.bits == 64) {
      out[t.column].percentiles[t.slot] = FromOrderedKey(t.prefix);
      t.done = true;
    }
  }
}

}  // namespace

double ColumnStatistics::mean() const {
  return count > 0 ? sum / static_cast<double>(count) : std::numeric_limits<double>::quiet_NaN();
}

std::vector<ColumnStatistics> SummarizeColumns(const ColumnSource& source, std::size_t columns,
                                               const std::vector<double>& percents,
                                               std::size_t budget_bytes) {
  std::vector<ColumnStatistics> out(columns);
  for (ColumnStatistics& c : out)
    c.percentiles.assign(percents.size(), std::numeric_limits<double>::quiet_NaN());

  // The first reading: counts, sums and ranges, and the finite values while they fit the budget.
  const std::size_t budget_values = std::max<std::size_t>(1, budget_bytes / sizeof(double));
  std::vector<std::vector<double>> held(columns);
  std::size_t held_values = 0;
  bool holding = true;
  source([&](std::size_t column, double v) {
    if (column >= columns) return;
    ColumnStatistics& c = out[column];
    ++c.count;
    c.sum += v;
    if (!std::isfinite(v)) return;
    ++c.finite;
    c.min = c.finite == 1 ? v : std::min(c.min, v);
    c.max = c.finite == 1 ? v : std::max(c.max, v);
    if (!holding) return;
    if (++held_values > budget_values) {
      holding = false;
      held = std::vector<std::vector<double>>(columns);
      return;
    }
    held[column].push_back(v);
  });

  if (holding) {
    for (std::size_t c = 0; c < columns; ++c) {
      std::vector<double>& v = held[c];
      for (std::size_t k = 0; k < percents.size() && !v.empty(); ++k) {
        const std::size_t rank = NearestRank(percents[k], v.size());
        std::nth_element(v.begin(), v.begin() + static_cast<long>(rank - 1), v.end());
        out[c].percentiles[k] = v[rank - 1];
      }
      v = {};
    }
    return out;
  }

  // Too many to hold: narrow every percentile by digits, in batches that fit the budget.
  std::vector<Target> targets;
  for (std::size_t c = 0; c < columns; ++c) {
    const auto n = static_cast<std::size_t>(out[c].finite);
    for (std::size_t k = 0; k < percents.size() && n > 0; ++k) {
      const std::size_t rank = NearestRank(percents[k], n);
      if (rank == n) {
        out[c].percentiles[k] = out[c].max == 0 ? 0.0 : out[c].max;
      } else if (rank == 1) {
        out[c].percentiles[k] = out[c].min == 0 ? 0.0 : out[c].min;
      } else {
        targets.push_back({c, k, rank, 0, n, 0, false});
      }
    }
  }
  for (;;) {
    std::vector<Target*> batch;
    std::vector<bool> collect;
    std::size_t bytes = 0;
    for (Target& t : targets) {
      if (t.done) continue;
      const std::size_t held_bytes = t.candidates * sizeof(double);
      const bool whole = held_bytes <= budget_bytes / 2;
      const std::size_t need = whole ? held_bytes : kHistogramBytes;
      if (!batch.empty() && bytes + need > budget_bytes) continue;
      batch.push_back(&t);
      collect.push_back(whole);
      bytes += need;
    }
    if (batch.empty()) return out;
    NarrowBatch(source, batch, collect, out);
  }
}

}  // namespace talus
