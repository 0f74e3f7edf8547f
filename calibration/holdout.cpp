#include "calibration/holdout.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <random>
#include <set>

#include "common/error.hpp"
#include "ensemble/runner.hpp"
#include "fieldobs/samples.hpp"

namespace talus::calibration {
namespace {

// The run indices in a seeded Fisher-Yates order (as designs.cpp: platform-independent).
std::vector<std::size_t> Shuffled(std::size_t n, std::uint64_t seed) {
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 engine(seed);
  for (std::size_t k = n; k > 1; --k) std::swap(order[k - 1], order[engine() % k]);
  return order;
}

std::vector<std::string> InReleaseOrder(const ensemble::ReleaseSpec& release,
                                        std::vector<std::size_t> indices) {
  std::sort(indices.begin(), indices.end());
  std::vector<std::string> ids;
  for (std::size_t i : indices) ids.push_back(release.runs[i].id);
  return ids;
}

constexpr int kMinMembers = 2;  // as the objective: scalars score against >= 2 members

}  // namespace

RunSubset SelectRuns(const ensemble::ReleaseSpec& release,
                     const fieldobs::ObservationSet& observations,
                     const std::vector<std::string>& runs, bool keep_scene_wide) {
  std::set<std::string> wanted(runs.begin(), runs.end());
  for (const std::string& id : runs) {
    bool known = false;
    for (const ensemble::ReleaseRun& r : release.runs) known = known || r.id == id;
    if (!known) throw InputError("run '" + id + "' is not a run of the scene");
  }
  RunSubset out;
  out.release = release;
  out.release.runs.clear();
  for (const ensemble::ReleaseRun& r : release.runs)
    if (wanted.count(r.id)) out.release.runs.push_back(r);
  const auto keep = [&](const std::string& run) {
    return run.empty() ? keep_scene_wide : wanted.count(run) > 0;
  };
  out.observations.zones = observations.zones;
  for (const auto& o : observations.scalars)
    if (keep(o.run)) out.observations.scalars.push_back(o);
  for (const auto& o : observations.deposits)
    if (keep(o.run)) out.observations.deposits.push_back(o);
  return out;
}

std::vector<std::string> OtherRuns(const ensemble::ReleaseSpec& release,
                                   const std::vector<std::string>& runs) {
  const std::set<std::string> left(runs.begin(), runs.end());
  std::vector<std::string> out;
  for (const ensemble::ReleaseRun& r : release.runs)
    if (!left.count(r.id)) out.push_back(r.id);
  return out;
}

std::vector<std::string> PickRuns(const ensemble::ReleaseSpec& release, int k, std::uint64_t seed) {
  const std::size_t n = release.runs.size();
  if (k < 1 || static_cast<std::size_t>(k) >= n)
    throw InputError("cannot hold out " + std::to_string(k) + " of " + std::to_string(n) +
                     " runs (1 .. " + std::to_string(n > 0 ? n - 1 : 0) + ")");
  std::vector<std::size_t> order = Shuffled(n, seed);
  order.resize(static_cast<std::size_t>(k));
  return InReleaseOrder(release, order);
}

std::vector<std::vector<std::string>> Folds(const ensemble::ReleaseSpec& release, int k,
                                            std::uint64_t seed) {
  const std::size_t n = release.runs.size();
  if (k < 2 || static_cast<std::size_t>(k) > n)
    throw InputError("cannot split " + std::to_string(n) + " runs into " + std::to_string(k) +
                     " folds (2 .. " + std::to_string(n) + ")");
  const std::vector<std::size_t> order = Shuffled(n, seed);
  std::vector<std::vector<std::size_t>> folds(static_cast<std::size_t>(k));
  for (std::size_t i = 0; i < n; ++i) folds[i % folds.size()].push_back(order[i]);
  std::vector<std::vector<std::string>> out;
  for (const auto& fold : folds) out.push_back(InReleaseOrder(release, fold));
  return out;
}

HeldOutScores ScoreRuns(const Scene& scene, const RunSubset& subset, const GroundTable& fitted,
                        const GroundTable* reference, int threads, bool episodes,
                        const EnsembleRunner& runner,
                        const std::vector<ensemble::Block>* fitted_blocks) {
  const auto t0 = std::chrono::steady_clock::now();
  HeldOutScores out;
  for (const ensemble::ReleaseRun& r : subset.release.runs) out.runs.push_back(r.id);
  ensemble::EnsembleOptions options;
  options.threads = threads;
  options.episodes = episodes;
  fieldobs::AddRecordersFor(subset.observations, scene.terrain, subset.release, options);
  const auto run = [&](const GroundTable& table, const ensemble::ReleaseSpec& release,
                       fieldobs::EnsembleSamples* samples) {
    Scene edited = scene;  // shares terrain and shapes; only the ground table differs
    edited.ground = table;
    out.rocks += RunWith(runner, edited, release, options, samples).rocks;
  };
  fieldobs::EnsembleSamples with_fitted(subset.release), with_reference(subset.release);
  if (fitted_blocks) {
    ensemble::ReleaseSpec shaped = subset.release;
    shaped.blocks = *fitted_blocks;
    run(fitted, shaped, &with_fitted);
  } else {
    run(fitted, subset.release, &with_fitted);
  }
  if (reference) run(*reference, subset.release, &with_reference);
  fieldobs::ValidationOptions validation;
  validation.min_members = kMinMembers;
  const fieldobs::ValidationReport report = fieldobs::Validate(
      subset.observations, with_fitted, reference ? &with_reference : nullptr, validation);
  out.observations = report.observations;
  for (const fieldobs::KindSummary& k : report.kinds) {
    HeldOutKind kind;
    kind.kind = k.kind;
    kind.unit = k.unit;
    kind.observations = k.observations;
    kind.scored = k.scored;
    kind.fitted = k.mean_score;
    kind.reference = reference ? k.mean_reference_score : fieldobs::kNaN;
    out.kinds.push_back(kind);
  }
  out.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

std::string HeldOutScores::Report() const {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "  %-24s %8s %14s %14s\n", "kind", "scored", "fitted",
                "reference");
  out += line;
  for (const HeldOutKind& k : kinds) {
    std::snprintf(line, sizeof line, "  %-24s %8d %11.4g %-2s %11.4g %-2s\n", k.kind.c_str(),
                  k.scored, k.fitted, k.unit.c_str(), k.reference, k.unit.c_str());
    out += line;
  }
  return out;
}

std::vector<HeldOutKind> PoolKinds(const std::vector<HeldOutScores>& sets) {
  std::vector<HeldOutKind> kinds;
  std::vector<double> fitted_sum, reference_sum;
  std::vector<int> reference_count;
  for (const HeldOutScores& set : sets)
    for (const fieldobs::ObservationScore& o : set.observations) {
      std::size_t k = 0;
      while (k < kinds.size() && kinds[k].kind != o.kind) ++k;
      if (k == kinds.size()) {
        kinds.push_back({o.kind, o.unit, 0, 0, fieldobs::kNaN, fieldobs::kNaN});
        fitted_sum.push_back(0);
        reference_sum.push_back(0);
        reference_count.push_back(0);
      }
      ++kinds[k].observations;
      if (!o.scored) continue;
      ++kinds[k].scored;
      fitted_sum[k] += o.score;
      if (std::isfinite(o.reference_score)) {
        reference_sum[k] += o.reference_score;
        ++reference_count[k];
      }
    }
  for (std::size_t k = 0; k < kinds.size(); ++k) {
    if (kinds[k].scored > 0) kinds[k].fitted = fitted_sum[k] / kinds[k].scored;
    if (reference_count[k] == kinds[k].scored && kinds[k].scored > 0)
      kinds[k].reference = reference_sum[k] / reference_count[k];
  }
  return kinds;
}

}  // namespace talus::calibration
