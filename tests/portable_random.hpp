#pragma once
// Random numbers that are the same with every standard library, for tests whose thresholds were
// measured on their draws: std::mt19937_64 is fully specified, std::uniform_real_distribution,
// std::normal_distribution and std::uniform_int_distribution are not. Drop-in objects called
// with the generator, like the standard distributions.

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>

namespace talus::testing {

// [0, 1) from the top 53 bits of one draw.
inline double Uniform01(std::mt19937_64& rng) {
  return static_cast<double>(rng() >> 11) * 0x1.0p-53;
}

// Uniform on [a, b) (b itself can come out for float after rounding, as with the standard one).
template <class T = double>
struct UniformReal {
  T a = 0, b = 1;
  UniformReal(T lo, T hi) : a(lo), b(hi) {}
  T operator()(std::mt19937_64& rng) const {
    return static_cast<T>(a + (b - a) * Uniform01(rng));
  }
};

// Normal by Box-Muller (cosine branch): two draws per value.
struct Normal {
  double mean = 0, sd = 1;
  Normal() = default;
  Normal(double m, double s) : mean(m), sd(s) {}
  double operator()(std::mt19937_64& rng) const {
    const double u1 = 1 - Uniform01(rng);  // (0, 1]
    const double u2 = Uniform01(rng);
    return mean + sd * std::sqrt(-2 * std::log(u1)) * std::cos(2 * std::numbers::pi * u2);
  }
};

// Uniform on the integers lo .. hi (the modulo's bias is below 2^-60 for the small ranges here).
struct UniformInt {
  int lo = 0, hi = 1;
  UniformInt(int l, int h) : lo(l), hi(h) {}
  int operator()(std::mt19937_64& rng) const {
    return lo + static_cast<int>(rng() % static_cast<std::uint64_t>(hi - lo + 1));
  }
};

}  // namespace talus::testing
