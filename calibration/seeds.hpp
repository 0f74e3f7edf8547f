#pragma once
// Seed refits: the fitted parameters' dependence on the particular rocks, the part of their error
// that the bootstrap over runs (bootstrap.hpp) cannot see.
//
// Every evaluation of a calibration re-runs the same rocks (common random numbers), so the
// objective is a deterministic but rough function of the parameters, and the optimum sits in a
// dip of it that every bootstrap resample shares: the bootstrap's refits start there and stay
// near it. With another release seed (other rocks, every other input the same) the dips move, and
// so does the fit. The seed refits refit the whole problem S times, with the release seeds
// seed + 1 .. seed + S (the other seeds of the roughness measurement, roughness.hpp), each by
// BOBYQA from the optimum on the bootstrap's lattice and budget (RefitFromOptimum); the standard
// deviation of the S refits measures that dependence.
//
// The stated standard error combines the two as independent sources,
// se = sqrt(se_boot^2 + se_seed^2): the bootstrap's spread comes from which runs are observed
// (the rocks held), the seeds' from which rocks are simulated (the runs held). An sd from S
// values is itself uncertain by a relative ~1/sqrt(2 (S - 1)) (normal values); se_seed is the
// refits' sd inflated by that one standard error, sd (1 + 1/sqrt(2 (S - 1))), so that a small S
// errs towards a wider interval rather than a narrower one. The combined interval widens each
// side of the bootstrap's percentile interval (which may be asymmetric about the fit) by the
// seeds' part in quadrature: fitted - sqrt((fitted - lower_boot)^2 + (z se_seed)^2) to
// fitted + sqrt((upper_boot - fitted)^2 + (z se_seed)^2), z the normal quantile of the
// bootstrap's level, clamped to the bounds; with se_seed = 0 it is the bootstrap's interval.
// Refits run one after the other, each evaluation with the objective's threads, so the result is
// bit-identical for any thread count and for a resumed calibration.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "calibration/bootstrap.hpp"
#include "calibration/objective.hpp"

namespace talus::calibration {

struct SeedRefitOptions {
  int seeds = 0;  // S; 0: no seed refits
  static constexpr int kMaxSeeds = 1000;
  bool IsValid(std::string* why) const;
};

struct SeedRefits {
  int seeds = 0;
  double level = 0.95;
  std::vector<std::string> names;
  std::vector<std::uint64_t> release_seeds;  // seed + 1 .. seed + S
  std::vector<bool> identified;              // the bootstrap's: held coordinates are not refitted
  Eigen::MatrixXd refits;                    // S x n: each seed's fitted values (physical units)
  Eigen::MatrixXd refits_unit;               // S x n: the same in unit coordinates
  Eigen::VectorXd sd, sd_unit;               // sd over the seeds; NaN if unidentified
  Eigen::VectorXd seed_standard_error;       // sd (1 + 1/sqrt(2 (S - 1))), physical units
  Eigen::VectorXd combined_standard_error;   // sqrt(bootstrap's^2 + seed_standard_error^2)
  Eigen::VectorXd combined_standard_error_unit;
  Eigen::VectorXd fitted;        // the values at the optimum, the interval's centre
  Eigen::VectorXd lower, upper;  // the bootstrap's interval widened by z seed_standard_error
  int refits_at_budget = 0;
  int evaluations = 0;  // evaluations run (each seed's repeated points answered from a cache)
  double wall_time_s = 0;
  std::string note;
  std::string Report() const;  // a few lines for people
};

// The seed refits from the bootstrap's optimum `bootstrap.u`, with the refit options (`refit`:
// first step, tolerances, budget, lattice) of that bootstrap, combined with its standard errors.
// Throws what the objective throws, and std::invalid_argument for invalid options.
SeedRefits RefitWithOtherSeeds(const Objective& objective, const Bootstrap& bootstrap,
                               const BootstrapOptions& refit, const SeedRefitOptions& options);

}  // namespace talus::calibration
