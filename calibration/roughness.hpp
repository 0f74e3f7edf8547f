#pragma once
// How rough the objective of a chaotic ensemble is, and which parameters the observations see.
//
// Roughness: with common random numbers the objective is a deterministic function of the
// parameters, but a tiny change of a parameter changes which way some rock turns at some impact,
// and its score jumps. MeasureRoughness re-evaluates at relative steps h (fractions of each
// coordinate's range) and with other seeds. A smooth objective changes by about |grad| h; the
// change at the smallest steps, where that is negligible, is the roughness (noise level) of the
// objective. Finite-difference steps and tolerances are chosen above it.
//
// Identifiability: a parameter whose profile (the objective along its coordinate from 0 to 1, the
// others at the optimum) changes by no more than a few times the noise level -- the larger of the
// roughness and the spread over other seeds, which is what a parameter that only scrambles which
// way rocks turn can do -- is not constrained by the observations: it is reported unidentified.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "calibration/objective.hpp"

namespace talus::calibration {

struct RoughnessOptions {
  std::vector<double> steps = {1e-4, 1e-3, 1e-2, 1e-1};  // relative to each coordinate's range
  int seeds = 2;  // evaluations with other release seeds (seed + 1, seed + 2, ...)
  // The finite-difference step is the smallest step whose typical change is at least
  // signal_to_noise times the roughness (the largest step when none is).
  double signal_to_noise = 10;
  bool IsValid(std::string* why) const;
};

struct RoughnessReport {
  double value = kNaN;  // f(u)
  std::vector<double> steps;
  // change[s][j] = |f(u +- steps[s] e_j) - f(u)| (the step goes inwards at a bound).
  std::vector<std::vector<double>> change;
  // The roughness: the largest change at the smallest step; 0 for a smooth objective there.
  double noise = 0;
  // Objective values with other seeds (other rocks) and their standard deviation: the sampling
  // noise of the ensemble, which common random numbers remove from comparisons between vectors.
  std::vector<double> seed_values;
  double seed_sd = kNaN;
  // The noise level identifiability is judged against: max(noise, seed_sd).
  double level() const { return std::isnan(seed_sd) ? noise : std::max(noise, seed_sd); }
  // Whether the level is sampling noise, which falls as 1/sqrt(rocks) (RocksToIdentify's
  // premise): the seeds' spread, or the roughness at a step of at most kSamplingNoiseStep. The
  // smooth objective changes by its slope x the step, about a profile's range x the step, so
  // there by a thousandth of the range; at a step of 1e-2 by a hundredth of it (a tenth where the
  // objective is ten times as steep as on average), which is of the order of a threshold that
  // matters and does not fall with the rocks.
  bool LevelIsSamplingNoise() const {
    return (!std::isnan(seed_sd) && seed_sd >= noise) ||
           (!steps.empty() && steps.front() <= kSamplingNoiseStep);
  }
  static constexpr double kSamplingNoiseStep = 1e-3;
  double fd_step = kNaN;   // recommended finite-difference step (unit coordinates)
  double ftol_abs = kNaN;  // recommended absolute tolerance on f: 2 x noise
  int evaluations = 0;
  double wall_time_s = 0;
  std::string Report() const;  // a few lines for people
};

RoughnessReport MeasureRoughness(const Objective& objective, const Eigen::VectorXd& u,
                                 const RoughnessOptions& options = {});

struct ProfileOptions {
  int points = 5;                // evaluations along each coordinate, 0 .. 1 evenly
  // Identified when the profile's range exceeds this x noise, and what the noise alone spans over
  // the profile's values (NoiseOnlyRange; the larger from about 10 values on).
  double noise_multiple = 3;
  double relative_floor = 1e-6;  // ... and this x |f(u)| (for a noise of 0)
};

struct ParameterProfile {
  std::string name;
  std::vector<double> u, values, f;  // along the coordinate
  double range = 0;                  // max - min of the data term (f less its prior)
  // What range had to exceed: the larger of noise_multiple x noise and NoiseOnlyRange over the
  // values it spans (f(u)'s and each feasible point's other than u), or the relative floor.
  double threshold = 0;
  bool identified = false;
  // The rocks per run at which this profile would just reach its threshold (RocksToIdentify);
  // NaN when the threshold is not the noise's (a noise of 0) or the range is 0.
  double rocks_to_identify = kNaN;
  // The range is no larger than the profile's values would span from noise alone
  // (NoiseOnlyRange): it may be noise, which falls with the rocks; then rocks_to_identify is too
  // few, and no number of rocks identifies it. Such a profile is never identified.
  bool within_noise = false;
};

// The rocks-per-run rule. The noise level an objective is judged against falls as 1/sqrt(rocks)
// (each run's score is a mean over its rocks; with common random numbers a small step moves a
// share of them), while a profile's range is the smooth objective's and does not depend on the
// rocks. A profile of range r judged against a threshold t measured with R rocks per run reaches
// it at R (t / r)^2 rocks per run. That is a lower bound where r is partly noise.
double RocksToIdentify(double range, double threshold, double rocks_per_run);
// Beyond this many rocks per run the rule's answer is "none that a calibration can afford" (a
// range that is a rounding residue would otherwise ask for 10^30 rocks).
constexpr double kMostRocksPerRun = 1e6;
// The expected range of n independent normal draws of standard deviation `sd`: d2(n) sd, with
// d2 the range constant of quality control (1.128 for 2 draws, 2.326 for 5). What a profile of n
// points spans from noise alone, its far points being nearly independent draws of the ensemble's
// noise.
double NoiseOnlyRange(int points, double sd);

// Profiles every coordinate through u (f(u) given: it is not re-evaluated), with `noise` the
// noise level from MeasureRoughness (RoughnessReport::level()).
std::vector<ParameterProfile> ProfileParameters(const Objective& objective,
                                                const Eigen::VectorXd& u, double f_u, double noise,
                                                const ProfileOptions& options = {});

}  // namespace talus::calibration
