#pragma once
// Space-filling start points in the unit cube for multi-start calibration: a seeded Latin
// hypercube and a Sobol sequence with a seeded digital shift. Deterministic on every platform.

#include <Eigen/Core>
#include <cstdint>
#include <string>

namespace talus::calibration {

// n points (rows) in [0, 1)^d: each coordinate's n strata [k/n, (k+1)/n) hold one point each.
Eigen::MatrixXd LatinHypercube(int n, int d, std::uint64_t seed);

// The first n points (rows) of the d-dimensional Sobol sequence (Joe & Kuo 2008 direction numbers,
// Gray-code order, as SciPy's unscrambled Sobol) XOR-shifted by seeded random digits (seed 0: no
// shift). The first 2^k points of each coordinate lie one in each of 2^k equal strata.
// d <= kMaxSobolDimension.
constexpr int kMaxSobolDimension = 16;
Eigen::MatrixXd Sobol(int n, int d, std::uint64_t seed);

}  // namespace talus::calibration
