#pragma once
// Scores of a simulated ensemble against an event's observations: per observation (the rocks of
// its run are the predictive distribution), per kind, and overall, with two baselines -- a
// reference parameter set (the seed paper's Table 1 by default) and the observations' own
// climatology (the other runs' observed values, leave-one-out) -- so that a user sees at once
// whether the model explains more than "it usually goes about this far".

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "ensemble/release.hpp"
#include "fieldobs/observations.hpp"
#include "fieldobs/samples.hpp"
#include "fieldobs/scores.hpp"

namespace talus::fieldobs {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// One observation with its score. Scalars: the CRPS (fair ensemble estimator) and the statistics
// of ScalarScore. Deposits: `score` is the energy score (m) of the observed rest position against
// the simulated end positions; `mean` is the distance from the ensemble's centroid to the
// observation, `sd` the ensemble's rms distance from its centroid; q05, q95, median are of the
// simulated rocks' distances to the observation; pit is NaN and inside_90 says whether the
// observation lies within the 90 % quantile of the ensemble's distances from its centroid.
struct ObservationScore {
  std::string kind;  // a Quantity's name, or "deposit"
  std::string unit;
  std::string run;
  std::string where;  // "file:line"
  double observed = kNaN;
  Eigen::Vector2d observed_xy_m = Eigen::Vector2d::Constant(kNaN);  // deposits
  bool scored = false;
  std::string not_scored = {};  // why, when not scored
  int members = 0;
  double score = kNaN;  // CRPS or energy score, in `unit`
  double pit = kNaN;
  double mean = kNaN, median = kNaN, sd = kNaN, q05 = kNaN, q95 = kNaN;
  bool inside_90 = false;
  double bias = kNaN;               // scalars: mean - observed
  double reference_score = kNaN;    // the same score with the reference parameter set
  double climatology_score = kNaN;  // the same score of the leave-one-out climatology
};

// Per kind: means over the scored observations, skills, and the PIT histogram (scalars).
struct KindSummary {
  std::string kind, unit;
  int observations = 0;  // in the event
  int scored = 0;
  double mean_score = kNaN;
  double mean_reference_score = kNaN;
  double mean_climatology_score = kNaN;
  double skill_vs_reference = kNaN;    // 1 - mean_score / mean_reference_score
  double skill_vs_climatology = kNaN;  // 1 - mean_score / mean_climatology_score
  double inside_90_fraction = kNaN;    // ideal 0.9
  double mean_bias = kNaN;             // scalars
  double mean_sd = kNaN;
  PitHistogram pit;  // empty counts for deposits or fewer than 2 scored
};

struct ValidationReport {
  std::vector<ObservationScore>
      observations;                // in the order of the ObservationSet (scalars, then deposits)
  std::vector<KindSummary> kinds;  // in order of first appearance
  int observations_scored = 0;
  // Means over kinds of the kinds' skills (kinds without a baseline are left out).
  double skill_vs_reference = kNaN;
  double skill_vs_climatology = kNaN;

  std::string BriefReport() const;  // one line
  std::string FullReport() const;   // a table per kind, for people
};

struct ValidationOptions {
  std::uint64_t seed = 1;  // for the PITs' tie-breaking uniforms: scores are deterministic
  int min_members = 2;     // fewer simulated values: the observation is not scored
};

// Per block of the runs and scalar kind: how far the simulated mean lies from the observed, over
// the scored observations of that block's runs. A bias of opposite sign per block is what a
// ground table cannot remove and a block's shape can (docs/calibration.md, "Shape parameters").
struct BlockBias {
  std::string block;  // ensemble::Block::id; "[rock]" for runs without a block
  std::string kind, unit;
  int scored = 0;           // observations
  int runs = 0;             // the runs they belong to
  double mean_bias = kNaN;  // mean over the observations of (simulated mean - observed)
  // Its standard error over the runs (NaN below 2 runs), clustered by run as the calibration's
  // sandwich is: observations of one run (zones, segments, impacts) share its rocks and are not
  // independent. With b the mean bias and S_g the sum of (bias - b) over run g's observations,
  //   se^2 = G / (G - 1) * sum_g S_g^2 / scored^2,
  // which is sd / sqrt(G) for one observation per run. Runs of one block scatter (the Tschamut
  // plate's observed run-outs by 25 m), so a block's bias over 4 runs is uncertain by about
  // 12 m: judge a bias against it.
  double bias_standard_error = kNaN;
  double mean_score = kNaN;
};

// The biases of `scores` (of scalar observations of runs; others are left out) by the block of
// each observation's run in `release`, blocks in release order, then kinds in order of first
// appearance. Runs not in `release` are left out.
std::vector<BlockBias> BiasByBlock(const std::vector<ObservationScore>& scores,
                                   const ensemble::ReleaseSpec& release);

// Scores `observations` against `simulated`, and against `reference` when given (same rocks with
// the reference parameter set).
ValidationReport Validate(const ObservationSet& observations, const EnsembleSamples& simulated,
                          const EnsembleSamples* reference, const ValidationOptions& options = {});

}  // namespace talus::fieldobs
