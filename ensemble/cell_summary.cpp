#include "ensemble/cell_summary.hpp"

#include <algorithm>
#include <cmath>

namespace talus::ensemble {

// The memory the rasters state per passed cell and quantity (rasters.hpp, docs/scenes.md).
static_assert(sizeof(ValueSummary) == 32, "a cell summary is 32 bytes");

namespace {

// `using` would not take __extension__, which keeps -Wpedantic quiet.
__extension__ typedef unsigned __int128 UInt128;  // NOLINT(modernize-use-using)

constexpr double kQuantum = 0x1p24;  // fixed-point scale of the sum
constexpr double kLargest = 0x1p64;  // |v| beyond this is clamped in the sum

}  // namespace

void ValueSummary::Add(float value) {
  if (!std::isfinite(value)) return;
  if (value == 0.0f) value = 0.0f;  // -0 as +0: min and max keep no trace of the order
  const double clamped = std::clamp(static_cast<double>(value), -kLargest, kLargest);
  sum_ += static_cast<Int128>(std::nearbyint(clamped * kQuantum));
  min_ = count_ == 0 ? value : std::min(min_, value);
  max_ = count_ == 0 ? value : std::max(max_, value);
  ++count_;
}

void ValueSummary::Merge(const ValueSummary& other) {
  if (other.count_ == 0) return;
  sum_ += other.sum_;
  min_ = count_ == 0 ? other.min_ : std::min(min_, other.min_);
  max_ = count_ == 0 ? other.max_ : std::max(max_, other.max_);
  count_ += other.count_;
}

double ValueSummary::mean() const {
  return count_ > 0 ? static_cast<double>(sum_) / kQuantum / static_cast<double>(count_) : 0.0;
}

void ValueSummary::Serialize(ByteWriter& out) const {
  out.Put(count_);
  out.Put(min_);
  out.Put(max_);
  out.Put(static_cast<std::uint64_t>(static_cast<UInt128>(sum_) >> 64));
  out.Put(static_cast<std::uint64_t>(sum_));
}

ValueSummary ValueSummary::Deserialize(ByteReader& in) {
  ValueSummary s;
  s.count_ = in.Get<std::int64_t>();
  s.min_ = in.Get<float>();
  s.max_ = in.Get<float>();
  const auto high = in.Get<std::uint64_t>();
  const auto low = in.Get<std::uint64_t>();
  s.sum_ = static_cast<Int128>((static_cast<UInt128>(high) << 64) | low);
  if (s.count_ < 0 || (s.count_ > 0 && !(s.min_ <= s.max_))) in.Fail();
  return s;
}

}  // namespace talus::ensemble
