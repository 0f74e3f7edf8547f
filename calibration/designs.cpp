#include "calibration/designs.hpp"

#include <array>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

namespace talus::calibration {
namespace {

// A uniform double in [0, 1) from 53 bits: identical on every platform (unlike
// std::uniform_real_distribution).
double Uniform(std::mt19937_64& engine) { return double(engine() >> 11) * 0x1.0p-53; }

// Joe & Kuo (2008), new-joe-kuo-6.21201: degree s, coefficients a and initial m_1 .. m_s of the
// primitive polynomials of dimensions 2 .. 16 (dimension 1 is the van der Corput sequence).
struct Direction {
  int s;
  unsigned a;
  std::array<unsigned, 6> m;
};
constexpr std::array<Direction, kMaxSobolDimension - 1> kDirections = {{
    {1, 0, {1}},
    {2, 1, {1, 3}},
    {3, 1, {1, 3, 1}},
    {3, 2, {1, 1, 1}},
    {4, 1, {1, 1, 3, 3}},
    {4, 4, {1, 3, 5, 13}},
    {5, 2, {1, 1, 5, 5, 17}},
    {5, 4, {1, 1, 5, 5, 5}},
    {5, 7, {1, 1, 7, 11, 19}},
    {5, 11, {1, 1, 5, 1, 1}},
    {5, 13, {1, 1, 1, 3, 11}},
    {5, 14, {1, 3, 5, 5, 31}},
    {6, 1, {1, 3, 3, 9, 7, 49}},
    {6, 13, {1, 1, 1, 15, 21, 21}},
    {6, 16, {1, 3, 1, 13, 27, 49}},
}};
constexpr int kBits = 32;

}  // namespace

Eigen::MatrixXd LatinHypercube(int n, int d, std::uint64_t seed) {
  if (n < 1 || d < 1) throw std::invalid_argument("LatinHypercube: n and d must be >= 1");
  std::mt19937_64 engine(seed);
  Eigen::MatrixXd points(n, d);
  std::vector<int> strata(static_cast<std::size_t>(n));
  for (int j = 0; j < d; ++j) {
    std::iota(strata.begin(), strata.end(), 0);
    for (int k = n - 1; k > 0; --k)  // Fisher-Yates
      std::swap(strata[static_cast<std::size_t>(k)],
                strata[static_cast<std::size_t>(engine() % static_cast<std::uint64_t>(k + 1))]);
    for (int k = 0; k < n; ++k)
      points(k, j) = (strata[static_cast<std::size_t>(k)] + Uniform(engine)) / n;
  }
  return points;
}

Eigen::MatrixXd Sobol(int n, int d, std::uint64_t seed) {
  if (n < 1 || d < 1 || d > kMaxSobolDimension)
    throw std::invalid_argument("Sobol: n must be >= 1 and d in 1 .. 16");
  // Direction integers V[j][k], k = 1 .. kBits, scaled by 2^kBits.
  std::vector<std::array<std::uint32_t, kBits + 1>> v(static_cast<std::size_t>(d));
  for (int k = 1; k <= kBits; ++k) v[0][k] = 1u << (kBits - k);
  for (int j = 1; j < d; ++j) {
    const Direction& dir = kDirections[static_cast<std::size_t>(j - 1)];
    auto& vj = v[static_cast<std::size_t>(j)];
    for (int k = 1; k <= dir.s; ++k) vj[k] = dir.m[static_cast<std::size_t>(k - 1)] << (kBits - k);
    for (int k = dir.s + 1; k <= kBits; ++k) {
      std::uint32_t x = vj[k - dir.s] ^ (vj[k - dir.s] >> dir.s);
      for (int i = 1; i < dir.s; ++i)
        if ((dir.a >> (dir.s - 1 - i)) & 1u) x ^= vj[k - i];
      vj[k] = x;
    }
  }
  std::vector<std::uint32_t> shift(static_cast<std::size_t>(d), 0);
  if (seed != 0) {
    std::mt19937_64 engine(seed);
    for (auto& s : shift) s = static_cast<std::uint32_t>(engine() >> 32);
  }
  Eigen::MatrixXd points(n, d);
  std::vector<std::uint32_t> x(static_cast<std::size_t>(d), 0);
  for (int i = 0; i < n; ++i) {
    if (i > 0) {
      // Gray code: flip the direction of the rightmost zero bit of i - 1.
      int c = 1;
      for (unsigned value = static_cast<unsigned>(i - 1); value & 1u; value >>= 1) ++c;
      for (int j = 0; j < d; ++j)
        x[static_cast<std::size_t>(j)] ^= v[static_cast<std::size_t>(j)][c];
    }
    for (int j = 0; j < d; ++j)
      points(i, j) =
          double(x[static_cast<std::size_t>(j)] ^ shift[static_cast<std::size_t>(j)]) * 0x1.0p-32;
  }
  return points;
}

}  // namespace talus::calibration
