#include "ensemble/cell_summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace talus::ensemble {

// The memory the rasters state per passed cell and quantity (rasters.hpp, docs/scenes.md).
static_assert(sizeof(ValueSummary) == 64, "a cell summary is 64 bytes besides its bins");

namespace {

// `using` would not take __extension__, which keeps -Wpedantic quiet.
__extension__ typedef unsigned __int128 UInt128;  // NOLINT(modernize-use-using)

constexpr int kShift = 23 - ValueSummary::kMantissaBits;  // float mantissa bits dropped
constexpr double kQuantum = 0x1p24;                       // fixed-point scale of the sum
constexpr double kLargest = 0x1p64;                       // |v| beyond this is clamped in the sum

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

}  // namespace

double ValueSummary::RelativeErrorAt(int level) {
  return std::ldexp(1.0, -(kMantissaBits + 1 - level));
}

int ValueSummary::BinOf(float value, int level) {
  if (value == 0.0f) value = 0.0f;  // -0 and +0 share a bin
  const std::uint32_t bits = BitsOf(value);
  const auto magnitude = static_cast<int>((bits & 0x7fffffffu) >> (kShift + level));
  return (bits >> 31) ? -magnitude - 1 : magnitude;
}

double ValueSummary::Midpoint(int bin, int level) {
  const int magnitude = bin >= 0 ? bin : -bin - 1;
  // The top bin's upper edge may pass the largest float: its bits are taken as an integer.
  const auto edge = [level](std::uint64_t m) {
    const std::uint64_t bits = m << (kShift + level);
    return bits >= 0x7f800000u ? std::ldexp(1.0, 128)
                               : static_cast<double>(FloatOf(static_cast<std::uint32_t>(bits)));
  };
  const double mid = 0.5 * (edge(static_cast<std::uint64_t>(magnitude)) +
                            edge(static_cast<std::uint64_t>(magnitude) + 1));
  return bin >= 0 ? mid : -mid;
}

void ValueSummary::CoarsenTo(int level) {
  while (level_ < level) {
    // A key's parent: its magnitude halved, the sign kept. Ascending keys keep ascending parents
    // (positive: m / 2 non-decreasing; negative, -m - 1 ascending as m falls: likewise), so equal
    // parents are neighbours.
    std::size_t out = 0;
    for (std::size_t k = 0; k < bins_.size(); ++k) {
      const int key = bins_[k].key;
      const int magnitude = key >= 0 ? key : -key - 1;
      const auto parent =
          static_cast<std::int16_t>(key >= 0 ? magnitude / 2 : -(magnitude / 2) - 1);
      if (out > 0 && bins_[out - 1].key == parent)
        bins_[out - 1].count += bins_[k].count;
      else
        bins_[out++] = Bin{parent, bins_[k].count};
    }
    bins_.resize(out);
    ++level_;
  }
}

void ValueSummary::CoarsenToFit() {
  while (bins_.size() > kMaxBins) CoarsenTo(level_ + 1);
}

void ValueSummary::Add(float value) {
  if (!std::isfinite(value)) return;
  const auto key = static_cast<std::int16_t>(BinOf(value, level_));
  auto at = std::lower_bound(bins_.begin(), bins_.end(), key,
                             [](const Bin& b, std::int16_t k) { return b.key < k; });
  if (at != bins_.end() && at->key == key)
    ++at->count;
  else
    bins_.insert(at, Bin{key, 1});
  CoarsenToFit();
  if (value == 0.0f) value = 0.0f;  // -0 as +0: min and max keep no trace of the order
  const double clamped = std::clamp(static_cast<double>(value), -kLargest, kLargest);
  sum_ += static_cast<Int128>(std::nearbyint(clamped * kQuantum));
  min_ = count_ == 0 ? value : std::min(min_, value);
  max_ = count_ == 0 ? value : std::max(max_, value);
  ++count_;
}

void ValueSummary::Merge(const ValueSummary& other) {
  if (other.count_ == 0) return;
  if (other.level_ > level_) {
    CoarsenTo(other.level_);
  } else if (other.level_ < level_) {
    ValueSummary coarser = other;
    coarser.CoarsenTo(level_);
    Merge(coarser);
    return;
  }
  std::vector<Bin> merged;
  merged.reserve(bins_.size() + other.bins_.size());
  auto a = bins_.cbegin();
  auto b = other.bins_.cbegin();
  while (a != bins_.cend() || b != other.bins_.cend()) {
    if (b == other.bins_.cend() || (a != bins_.cend() && a->key < b->key)) {
      merged.push_back(*a++);
    } else if (a == bins_.cend() || b->key < a->key) {
      merged.push_back(*b++);
    } else {
      merged.push_back({a->key, a->count + b->count});
      ++a;
      ++b;
    }
  }
  bins_ = std::move(merged);
  sum_ += other.sum_;
  min_ = count_ == 0 ? other.min_ : std::min(min_, other.min_);
  max_ = count_ == 0 ? other.max_ : std::max(max_, other.max_);
  count_ += other.count_;
  CoarsenToFit();
}

double ValueSummary::mean() const {
  return count_ > 0 ? static_cast<double>(sum_) / kQuantum / static_cast<double>(count_) : 0.0;
}

float ValueSummary::Quantile(double q) const {
  return AtRank(static_cast<std::int64_t>(std::ceil(q * static_cast<double>(count_))));
}

float ValueSummary::Percentile(int percent) const {
  const Int128 product = static_cast<Int128>(percent) * count_;
  return AtRank(static_cast<std::int64_t>((product + 99) / 100));
}

float ValueSummary::AtRank(std::int64_t rank) const {
  // The extreme ranks are known exactly.
  if (rank <= 1) return min_;
  if (rank >= count_) return max_;
  std::int64_t seen = 0;
  for (const Bin& bin : bins_) {
    seen += bin.count;
    if (seen >= rank) return std::clamp(static_cast<float>(Midpoint(bin.key, level_)), min_, max_);
  }
  return max_;
}

void ValueSummary::Serialize(ByteWriter& out) const {
  out.Put(count_);
  out.Put(min_);
  out.Put(max_);
  out.Put(static_cast<std::uint64_t>(static_cast<UInt128>(sum_) >> 64));
  out.Put(static_cast<std::uint64_t>(sum_));
  out.Put(level_);
  std::vector<std::int16_t> keys;
  std::vector<std::uint32_t> counts;
  for (const Bin& b : bins_) {
    keys.push_back(b.key);
    counts.push_back(b.count);
  }
  out.PutVector(keys);
  out.PutVector(counts);
}

ValueSummary ValueSummary::Deserialize(ByteReader& in) {
  ValueSummary s;
  s.count_ = in.Get<std::int64_t>();
  s.min_ = in.Get<float>();
  s.max_ = in.Get<float>();
  const auto high = in.Get<std::uint64_t>();
  const auto low = in.Get<std::uint64_t>();
  s.sum_ = static_cast<Int128>((static_cast<UInt128>(high) << 64) | low);
  s.level_ = in.Get<std::int32_t>();
  if (s.level_ < 0 || s.level_ > 31 - kShift || (s.count_ > 0 && !(s.min_ <= s.max_))) in.Fail();
  const auto keys = in.GetVector<std::int16_t>();
  const auto counts = in.GetVector<std::uint32_t>();
  if (keys.size() != counts.size()) in.Fail();
  std::int64_t total = 0;
  for (std::size_t k = 0; k < keys.size(); ++k) {
    if ((k > 0 && keys[k] <= keys[k - 1]) || counts[k] == 0) in.Fail();
    s.bins_.push_back({keys[k], counts[k]});
    total += counts[k];
  }
  if (total != s.count_ || s.bins_.size() > kMaxBins) in.Fail();
  return s;
}

}  // namespace talus::ensemble
