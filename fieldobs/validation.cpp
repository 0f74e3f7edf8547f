#include "fieldobs/validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>

#include "common/format.hpp"
#include "common/statistics.hpp"
#include "solver/random.hpp"

namespace talus::fieldobs {
namespace {

// The stream of the PITs' uniforms, apart from the rocks' streams of the same seed.
constexpr std::uint64_t kPitStream = 0x5049545049545049ULL;

void ScoreScalarObservation(const ScalarObservation& o, const EnsembleSamples& sim,
                            const EnsembleSamples* reference, double climatology_score, double u,
                            int min_members, ObservationScore& s) {
  const std::vector<double> values = sim.Values(o.quantity, o.run, o.zone);
  s.members = static_cast<int>(values.size());
  if (!sim.HasRun(o.run)) {
    s.not_scored = "no run '" + o.run + "' in the scene";
    return;
  }
  if (s.members < min_members) {
    s.not_scored = "only " + std::to_string(s.members) + " simulated values";
    return;
  }
  const ScalarScore score = ScoreScalar(values, o.value, u);
  s.scored = true;
  s.score = score.crps;
  s.pit = score.pit;
  s.mean = score.mean;
  s.median = score.median;
  s.sd = score.sd;
  s.q05 = score.q05;
  s.q95 = score.q95;
  s.inside_90 = score.inside_90;
  s.bias = score.bias;
  if (reference) {
    const std::vector<double> ref = reference->Values(o.quantity, o.run, o.zone);
    if (static_cast<int>(ref.size()) >= min_members) s.reference_score = CrpsEnsemble(ref, o.value);
  }
  s.climatology_score = climatology_score;
}

void ScoreDeposit(const DepositObservation& o, const EnsembleSamples& sim,
                  const EnsembleSamples* reference, double climatology_score, int min_members,
                  ObservationScore& s) {
  const std::vector<Eigen::Vector2d> ends = sim.EndPositions(o.run);
  s.members = static_cast<int>(ends.size());
  if (!sim.HasRun(o.run)) {
    s.not_scored = "no run '" + o.run + "' in the scene";
    return;
  }
  if (s.members < min_members) {
    s.not_scored = "only " + std::to_string(s.members) + " simulated rocks";
    return;
  }
  s.scored = true;
  s.score = EnergyScore(ends, o.xy_m);
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& e : ends) centroid += e;
  centroid /= double(ends.size());
  std::vector<double> to_observed, spread;
  for (const Eigen::Vector2d& e : ends) {
    to_observed.push_back((e - o.xy_m).norm());
    spread.push_back((e - centroid).norm());
  }
  s.mean = (centroid - o.xy_m).norm();
  double sum2 = 0;
  for (double d : spread) sum2 += d * d;
  s.sd = std::sqrt(sum2 / double(spread.size()));
  s.median = Quantile(to_observed, 0.5);
  s.q05 = Quantile(to_observed, 0.05);
  s.q95 = Quantile(to_observed, 0.95);
  s.inside_90 = s.mean <= Quantile(spread, 0.9);
  if (reference) {
    const std::vector<Eigen::Vector2d> ref = reference->EndPositions(o.run);
    if (static_cast<int>(ref.size()) >= min_members) s.reference_score = EnergyScore(ref, o.xy_m);
  }
  s.climatology_score = climatology_score;
}

// The report's numbers: "-" for one that does not exist.
std::string Number(double v, const char* format = "%.3g") {
  return FormatOrMissing(v, format, "-");
}

// Scalars' climatology: the other observations of the same quantity (leave-one-out), scored
// when there are at least min_members of them; NaN where there is none.
std::vector<double> ScalarClimatologyScores(const ObservationSet& observations, int min_members) {
  std::vector<double> scalar_climatology(observations.scalars.size(), kNaN);
  std::map<Quantity, std::vector<std::size_t>> by_quantity;
  for (std::size_t k = 0; k < observations.scalars.size(); ++k)
    by_quantity[observations.scalars[k].quantity].push_back(k);
  for (const auto& [quantity, indices] : by_quantity) {
    if (static_cast<int>(indices.size()) - 1 < min_members) continue;
    std::vector<double> values;
    for (std::size_t k : indices) values.push_back(observations.scalars[k].value);
    const std::vector<double> scores = LeaveOneOutCrps(values);
    for (std::size_t i = 0; i < indices.size(); ++i) scalar_climatology[indices[i]] = scores[i];
  }
  return scalar_climatology;
}

// Deposits' climatology: the other runs' observed displacements from their release, applied to
// this run's release (leave-one-out); none (NaN) for observations of the whole scene. Scored
// against this run's deposit, that is the energy score of this run's displacement against the
// others'.
std::vector<double> DepositClimatologyScores(const ObservationSet& observations,
                                             const EnsembleSamples& simulated, int min_members) {
  std::vector<double> deposit_climatology(observations.deposits.size(), kNaN);
  std::vector<std::size_t> indices;
  std::vector<Eigen::Vector2d> displacements;
  for (std::size_t k = 0; k < observations.deposits.size(); ++k)
    if (const auto start = simulated.StartOf(observations.deposits[k].run)) {
      indices.push_back(k);
      displacements.push_back(observations.deposits[k].xy_m - *start);
    }
  if (static_cast<int>(indices.size()) - 1 >= min_members) {
    const std::vector<double> scores = LeaveOneOutEnergyScores(displacements);
    for (std::size_t i = 0; i < indices.size(); ++i) deposit_climatology[indices[i]] = scores[i];
  }
  return deposit_climatology;
}

// Every scalar observation's score, with its leave-one-out climatology.
void ScoreScalars(const ObservationSet& observations, const EnsembleSamples& simulated,
                  const EnsembleSamples* reference, const ValidationOptions& options,
                  ValidationReport& report) {
  RockRandom uniforms(options.seed, kPitStream);
  const std::vector<double> scalar_climatology =
      ScalarClimatologyScores(observations, options.min_members);
  for (std::size_t k = 0; k < observations.scalars.size(); ++k) {
    const ScalarObservation& o = observations.scalars[k];
    ObservationScore s{.kind = ToString(o.quantity),
                       .unit = UnitOf(o.quantity),
                       .run = o.run,
                       .where = o.where,
                       .observed = o.value};
    const double u = uniforms.Uniform();  // drawn for every observation: scores do not shift
    ScoreScalarObservation(o, simulated, reference, scalar_climatology[k], u, options.min_members,
                           s);
    report.observations.push_back(s);
  }
}

// Every deposit observation's score, with its leave-one-out climatology.
void ScoreDeposits(const ObservationSet& observations, const EnsembleSamples& simulated,
                   const EnsembleSamples* reference, const ValidationOptions& options,
                   ValidationReport& report) {
  const std::vector<double> deposit_climatology =
      DepositClimatologyScores(observations, simulated, options.min_members);
  for (std::size_t k = 0; k < observations.deposits.size(); ++k) {
    const DepositObservation& o = observations.deposits[k];
    ObservationScore s{
        .kind = "deposit", .unit = "m", .run = o.run, .where = o.where, .observed_xy_m = o.xy_m};
    ScoreDeposit(o, simulated, reference, deposit_climatology[k], options.min_members, s);
    report.observations.push_back(s);
  }
}

// The per-kind summaries of the observation scores and the report's skill scores.
void SummarizeKinds(ValidationReport& report) {
  std::map<std::string, std::size_t> index;
  for (const ObservationScore& s : report.observations) {
    if (!index.count(s.kind)) {
      index[s.kind] = report.kinds.size();
      report.kinds.push_back({});
      report.kinds.back().kind = s.kind;
      report.kinds.back().unit = s.unit;
    }
    ++report.kinds[index[s.kind]].observations;
  }
  std::vector<double> ref_skills, clim_skills;
  for (KindSummary& kind : report.kinds) {
    std::vector<double> score, ref, clim, bias, sd, pits;
    int inside = 0;
    bool all_ref = true, all_clim = true;
    for (const ObservationScore& s : report.observations) {
      if (s.kind != kind.kind || !s.scored) continue;
      ++kind.scored;
      score.push_back(s.score);
      ref.push_back(s.reference_score);
      clim.push_back(s.climatology_score);
      all_ref = all_ref && !std::isnan(s.reference_score);
      all_clim = all_clim && !std::isnan(s.climatology_score);
      inside += s.inside_90;
      if (!std::isnan(s.bias)) bias.push_back(s.bias);
      sd.push_back(s.sd);
      if (!std::isnan(s.pit)) pits.push_back(s.pit);
    }
    report.observations_scored += kind.scored;
    if (kind.scored == 0) continue;
    kind.mean_score = Mean(score);
    kind.inside_90_fraction = double(inside) / kind.scored;
    kind.mean_bias = Mean(bias);
    kind.mean_sd = Mean(sd);
    // Baselines count only when every scored observation has one (same observations compared).
    if (all_ref) {
      kind.mean_reference_score = Mean(ref);
      if (kind.mean_reference_score > 0) {
        kind.skill_vs_reference = SkillScore(kind.mean_score, kind.mean_reference_score);
        ref_skills.push_back(kind.skill_vs_reference);
      }
    }
    if (all_clim) {
      kind.mean_climatology_score = Mean(clim);
      if (kind.mean_climatology_score > 0) {
        kind.skill_vs_climatology = SkillScore(kind.mean_score, kind.mean_climatology_score);
        clim_skills.push_back(kind.skill_vs_climatology);
      }
    }
    if (pits.size() >= 2) {
      const int bins = std::clamp(static_cast<int>(pits.size()) / 5, 2, 10);
      kind.pit = MakePitHistogram(pits, bins);
    }
  }
  report.skill_vs_reference = Mean(ref_skills);
  report.skill_vs_climatology = Mean(clim_skills);
}

}  // namespace

ValidationReport Validate(const ObservationSet& observations, const EnsembleSamples& simulated,
                          const EnsembleSamples* reference, const ValidationOptions& options) {
  ValidationReport report;
  ScoreScalars(observations, simulated, reference, options, report);
  ScoreDeposits(observations, simulated, reference, options, report);
  SummarizeKinds(report);
  return report;
}

std::string ValidationReport::BriefReport() const {
  char line[256];
  std::snprintf(line, sizeof line,
                "%d of %zu observations scored; skill vs reference %s, vs climatology %s",
                observations_scored, observations.size(), Number(skill_vs_reference).c_str(),
                Number(skill_vs_climatology).c_str());
  return line;
}

std::string ValidationReport::FullReport() const {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-26s %5s %10s %10s %10s %8s %8s %8s %10s %8s\n", "kind", "n",
                "score", "reference", "climatol.", "skill_r", "skill_c", "in 90%", "bias", "PIT p");
  out += line;
  for (const KindSummary& k : kinds) {
    const std::string name = k.kind + " (" + k.unit + ")";
    std::snprintf(line, sizeof line, "%-26s %2d/%-2d %10s %10s %10s %8s %8s %8s %10s %8s\n",
                  name.c_str(), k.scored, k.observations, Number(k.mean_score).c_str(),
                  Number(k.mean_reference_score).c_str(), Number(k.mean_climatology_score).c_str(),
                  Number(k.skill_vs_reference, "%.2f").c_str(),
                  Number(k.skill_vs_climatology, "%.2f").c_str(),
                  Number(k.inside_90_fraction, "%.2f").c_str(), Number(k.mean_bias).c_str(),
                  k.pit.counts.empty() ? "-" : Number(k.pit.p_value, "%.2g").c_str());
    out += line;
  }
  return out + BriefReport() + "\n";
}

std::vector<BlockBias> BiasByBlock(const std::vector<ObservationScore>& scores,
                                   const ensemble::ReleaseSpec& release) {
  std::map<std::string, std::string> block_of;  // run id -> block id
  for (const ensemble::ReleaseRun& r : release.runs)
    block_of[r.id] =
        r.block >= 0 ? release.blocks[static_cast<std::size_t>(r.block)].id : std::string("[rock]");
  std::vector<std::string> blocks;  // release order: the blocks, then runs without one
  for (const ensemble::Block& b : release.blocks) blocks.push_back(b.id);
  blocks.emplace_back("[rock]");
  std::vector<std::string> kinds;
  for (const ObservationScore& s : scores)
    if (s.scored && std::isfinite(s.bias) &&
        std::find(kinds.begin(), kinds.end(), s.kind) == kinds.end())
      kinds.push_back(s.kind);
  std::vector<BlockBias> out;
  for (const std::string& block : blocks)
    for (const std::string& kind : kinds) {
      BlockBias b;
      b.block = block;
      b.kind = kind;
      std::vector<double> bias;
      std::vector<std::string> run_of;  // per observation in `bias`
      double score = 0;
      for (const ObservationScore& s : scores) {
        const auto it = block_of.find(s.run);
        if (!s.scored || !std::isfinite(s.bias) || s.kind != kind || it == block_of.end() ||
            it->second != block)
          continue;
        b.unit = s.unit;
        bias.push_back(s.bias);
        run_of.push_back(s.run);
        score += s.score;
        ++b.scored;
      }
      if (b.scored == 0) continue;
      b.mean_bias = Mean(bias);
      b.mean_score = score / b.scored;
      std::map<std::string, double> by_run;  // S_g
      for (std::size_t i = 0; i < bias.size(); ++i) by_run[run_of[i]] += bias[i] - b.mean_bias;
      b.runs = static_cast<int>(by_run.size());
      if (b.runs >= 2) {
        double ss = 0;
        for (const auto& [run, sum] : by_run) ss += sum * sum;
        const double g = b.runs, n = b.scored;
        b.bias_standard_error = std::sqrt(g / (g - 1) * ss / (n * n));
      }
      out.push_back(b);
    }
  return out;
}

}  // namespace talus::fieldobs
