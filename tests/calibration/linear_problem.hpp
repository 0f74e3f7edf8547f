#pragma once
// A calibration objective whose residuals are a given function of the free parameters, with no
// rock run: the objective's EnsembleRunner is replaced by one that gives each run two identical
// "rocks" whose run-out makes that run's location residual exactly the value asked for. With
// one run-out observation y_g = 0 per run, unit weight and no normalisation, observation g of G
// has the factor c = 1 / G, a two-member ensemble of equal values x has CRPS |x| and CRPS 0 at its
// median, so x = sign(L) G L^2 gives the location residual L (and a spread residual of 0).
// Least-squares problems whose Jacobian, noise and covariance are known in closed form.

#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "calibration/objective.hpp"
#include "calibration/parameters.hpp"
#include "solver/shapes.hpp"

namespace talus::calibration::testing {

// The values of medium_hard's fields that the residuals may read (the free ones change).
struct GroundValues {
  double mu_min = 0, mu_max = 0, beta_1_s = 0;
};

// residual(values, g): run g's location residual.
using ResidualFn = std::function<double(const GroundValues& values, int run)>;

struct LinearProblem {
  Scene scene;
  ensemble::ReleaseSpec release;
  fieldobs::ObservationSet observations;
  // How many times the objective ran its "ensemble" (shared by copies of the runner).
  std::shared_ptr<std::atomic<int>> runs = std::make_shared<std::atomic<int>>(0);

  explicit LinearProblem(int groups) {
    Heightfield h;
    h.grid = {.nx = 3, .ny = 3, .x0_m = 0, .y0_m = 0, .dx_m = 10, .dy_m = 10};
    h.z_m.assign(9, 0.0);
    scene.terrain = Terrain(std::move(h), scene.ground.IndexOfName("medium_hard"));
    scene.rock = MakeRockShape(MakeBox(0.4, 0.4, 0.3), 2700);
    for (int g = 0; g < groups; ++g) {
      char id[32];
      std::snprintf(id, sizeof id, "run%d", g);
      ensemble::ReleaseRun run;
      run.id = id;
      run.xy_m = {10, 10};
      release.runs.push_back(run);
      observations.scalars.push_back({fieldobs::Quantity::kRunout, id, 0.0, id});
    }
    release.rocks_per_release = 2;
    release.seed = 1;
  }

  // With prior_weight > 0 the specs' own priors act (ObjectiveOptions::prior_weight).
  Objective Make(std::vector<ParameterSpec> specs, ResidualFn residual,
                 double prior_weight = 0) const {
    ObjectiveOptions options;
    options.prior_weight = prior_weight;
    options.normalise = false;
    options.threads = 1;
    const int groups = static_cast<int>(release.runs.size());
    const int medium_hard = scene.ground.IndexOfName("medium_hard");
    auto counter = runs;
    options.run_ensemble = [=](const Scene& s, const ensemble::ReleaseSpec& r,
                               const ensemble::EnsembleOptions&,
                               fieldobs::EnsembleSamples* samples) {
      ++*counter;
      const GroundParams& p = s.ground.params(medium_hard);
      const GroundValues values{p.mu_min, p.mu_max, p.beta_1_s};
      ensemble::EnsembleReport report;
      long rock = 0;
      for (int g = 0; g < static_cast<int>(r.runs.size()); ++g) {
        const double l = residual(values, g);
        for (int k = 0; k < 2; ++k) {
          ensemble::RockOutcome outcome;
          outcome.rock = rock++;
          outcome.release = g;
          outcome.result.runout_m = (l < 0 ? -1.0 : 1.0) * groups * l * l;
          samples->OnRock(outcome);
        }
      }
      report.rocks = rock;
      return report;
    };
    return Objective(scene, release, observations, std::move(specs), options);
  }
};

inline ParameterSpec Free(GroundField field, double lower, double upper) {
  ParameterSpec s;
  s.category = "medium_hard";
  s.field = field;
  s.lower = lower;
  s.upper = upper;
  return s;
}

// A deterministic draw, uniform on [-sqrt 3, sqrt 3) (variance 1), from a value and a run:
// independent between values that differ in any bit (splitmix64 of the value's bits and the run).
inline double NoiseAt(double value, int run) {
  std::uint64_t x;
  std::memcpy(&x, &value, sizeof x);
  x += 0x9e3779b97f4a7c15ull * static_cast<std::uint64_t>(run + 1);
  for (int round = 0; round < 2; ++round) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    x ^= x >> 31;
  }
  return std::sqrt(3.0) * (2.0 * static_cast<double>(x >> 11) * 0x1.0p-53 - 1.0);
}

}  // namespace talus::calibration::testing
