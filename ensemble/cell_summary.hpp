#pragma once
// The summary of one quantity (speed, energy, jump height) in one raster cell over the rocks that
// passed it: count, minimum, maximum, an exact sum, and a histogram on fixed log-spaced bins for
// percentiles (any integer percent 1 .. 99). Its size does not grow with the number of rocks: at
// most kMaxBins bins (2 kB), whatever the count and the range, and two summaries merge exactly
// (integer counts, integer sum), so the result does not depend on the order or the split of the
// rocks: threads, ranks and partial runs give the same bits.
//
// Bins: at level 0, a float's sign, exponent and first 6 mantissa bits, i.e. 64 bins per octave,
// each [lo, lo (1 + 2^-6)) at most; at level L, pairs of level L - 1 bins joined (64 / 2^L per
// octave). A summary is at the smallest level at which its values occupy at most kMaxBins bins:
// it coarsens (joins neighbouring pairs) when a value or a merge would exceed them. That level is
// a property of the set of values, not of their order (the number of occupied bins only grows
// with the set and only falls with the level), so the bits stay independent of order and split.
// A quantile is the bin's midpoint, clamped to [min, max], so
//     |Quantile(q) - exact nearest-rank quantile| <= 2^-(7 - L) |exact|
// (0.79 % at level 0, 1.6 % at 1, 3.1 % at 2), plus at most 1e-40 (the bins of subnormal floats);
// exact for the first and last rank (the minimum and maximum) and when every value is the same.
// 256 bins hold 4 octaves (a factor 16) at level 0, 8 at level 1 and 16 at level 2: a cell's
// speeds stay at level 0 or 1, its energies (with the squared speed and mixed block sizes) at
// 1 or 2.
// The sum is kept in fixed point with a quantum of 2^-24 (per value, |v| <= 2^64): the mean is
// within 2^-25 (3e-8) of the exact mean of the values, whatever the order.

#include <cstdint>
#include <vector>

#include "common/bytes.hpp"

namespace talus::ensemble {

// GCC and Clang; `using` would not take __extension__, which keeps -Wpedantic quiet.
__extension__ typedef __int128 Int128;  // NOLINT(modernize-use-using)

class ValueSummary {
 public:
  static constexpr int kMantissaBits = 6;  // 64 bins per octave at level 0
  static constexpr std::size_t kMaxBins = 256;
  // A bound on |Quantile - exact| / |exact| at level 0 (see above), and at `level`.
  static constexpr double kRelativeError = 1.0 / 128;
  static double RelativeErrorAt(int level);

  // Non-finite values are left out (they have no place in a mean or a percentile).
  void Add(float value);
  void Merge(const ValueSummary& other);

  std::int64_t count() const { return count_; }
  float min() const { return min_; }
  float max() const { return max_; }
  double mean() const;
  // The nearest-rank q-quantile (the smallest value with at least q of the values at or below
  // it), to within kRelativeError; requires count() > 0 and 0 < q <= 1.
  float Quantile(double q) const;
  // The nearest-rank `percent`-th percentile (rank ceil(percent * count / 100), computed in
  // integers, so that no rounding of percent / 100 moves it), to within kRelativeError; requires
  // count() > 0 and 1 <= percent <= 100.
  float Percentile(int percent) const;
  // Histogram bins held (memory: 8 bytes each), at most kMaxBins, and their level.
  std::size_t bins() const { return bins_.size(); }
  int level() const { return level_; }
  // The bound on this summary's quantiles' relative error: RelativeErrorAt(level()).
  double relative_error() const { return RelativeErrorAt(level_); }

  void Serialize(ByteWriter& out) const;
  static ValueSummary Deserialize(ByteReader& in);

  // The bin of a finite value at `level`, and a bin's midpoint (bins are ordered as their values
  // are).
  static int BinOf(float value, int level = 0);
  static double Midpoint(int bin, int level = 0);

 private:
  // The value of rank `rank` (1-based) in ascending order, to within kRelativeError.
  float AtRank(std::int64_t rank) const;
  // Joins neighbouring pairs of bins (one level up) until at most kMaxBins are left.
  void CoarsenToFit();
  // Joins neighbouring pairs of bins until the level is `level`.
  void CoarsenTo(int level);

  struct Bin {
    std::int16_t key;
    std::uint32_t count;
  };
  std::vector<Bin> bins_;   // ascending keys
  std::int32_t level_ = 0;  // here, in the padding before the 16-byte aligned sum: 64 bytes in all
  Int128 sum_ = 0;          // sum of round(v * 2^24)
  std::int64_t count_ = 0;
  float min_ = 0, max_ = 0;
};

}  // namespace talus::ensemble
