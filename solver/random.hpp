#pragma once
// Per-rock random streams: each rock's numbers depend on (seed, rock index) only, so results do
// not depend on which thread runs which rock.

#include <Eigen/Geometry>
#include <cstdint>
#include <random>

namespace talus {

class RockRandom {
 public:
  RockRandom(std::uint64_t seed, std::uint64_t rock_index);
  double Uniform();  // in [0, 1), 53 random bits, identical on every platform
  // Uniformly distributed rotation on SO(3) (Shoemake 1992, "Uniform random rotations").
  Eigen::Quaterniond Orientation();

 private:
  std::mt19937_64 engine_;
};

}  // namespace talus
