#pragma once
// The summary of one quantity (speed, energy, jump height) in one raster cell over the rocks that
// passed it: count, minimum, maximum and an exact sum, for the <quantity>_max and _mean rasters.
// Its size (32 bytes) does not grow with the number of rocks, and two summaries merge exactly
// (integer count, integer sum), so the result does not depend on the order or the split of the
// rocks: threads, ranks and partial runs give the same bits. The percentile rasters are taken
// exactly from the values themselves, spilled to disk (raster_spill.hpp).
// The sum is kept in fixed point with a quantum of 2^-24 (per value, |v| <= 2^64): the mean is
// within 2^-25 (3e-8) of the exact mean of the values, whatever the order.

#include <cstdint>

#include "common/bytes.hpp"

namespace talus::ensemble {

// GCC and Clang; `using` would not take __extension__, which keeps -Wpedantic quiet.
__extension__ typedef __int128 Int128;  // NOLINT(modernize-use-using)

class ValueSummary {
 public:
  // Non-finite values are left out (they have no place in a mean or a percentile).
  void Add(float value);
  void Merge(const ValueSummary& other);

  std::int64_t count() const { return count_; }
  float min() const { return min_; }
  float max() const { return max_; }
  double mean() const;

  void Serialize(ByteWriter& out) const;
  static ValueSummary Deserialize(ByteReader& in);

 private:
  Int128 sum_ = 0;  // sum of round(v * 2^24)
  std::int64_t count_ = 0;
  float min_ = 0, max_ = 0;
};

}  // namespace talus::ensemble
