#include "solver/random.hpp"

#include <cmath>
#include <numbers>

namespace talus {

RockRandom::RockRandom(std::uint64_t seed, std::uint64_t rock_index) {
  // std::seed_seq and std::mt19937_64 are fully specified by the standard: portable streams.
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32),
                    static_cast<std::uint32_t>(rock_index),
                    static_cast<std::uint32_t>(rock_index >> 32)};
  engine_.seed(seq);
}

double RockRandom::Uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

Eigen::Quaterniond RockRandom::Orientation() {
  const double u1 = Uniform(), u2 = Uniform(), u3 = Uniform();
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const double t2 = 2 * std::numbers::pi * u2, t3 = 2 * std::numbers::pi * u3;
  return Eigen::Quaterniond(b * std::cos(t3), a * std::sin(t2), a * std::cos(t2), b * std::sin(t3));
}

}  // namespace talus
