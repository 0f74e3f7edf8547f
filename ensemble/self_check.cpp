#include "ensemble/self_check.hpp"

#include <boost/math/distributions/normal.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

#include "common/statistics.hpp"
#include "ensemble/runner.hpp"

namespace talus::ensemble {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// What the statistics read from each rock of one run, in rock order.
struct Sample {
  std::vector<double> runout_m, max_speed_m_s, max_energy_kj, max_jump_m;
  std::vector<std::vector<double>> line_energy_kj;  // [line][rock], NaN where it did not cross
};

class SampleSink : public RockSink {
 public:
  SampleSink(Sample& sample, std::size_t lines) : sample_(sample) {
    sample_.line_energy_kj.assign(lines, {});
  }
  void OnRock(const RockOutcome& out) override {
    const RockResult& r = out.result;
    sample_.runout_m.push_back(r.runout_m);
    sample_.max_speed_m_s.push_back(r.max_speed_m_s);
    sample_.max_energy_kj.push_back(r.max_kinetic_energy_j / 1e3);
    sample_.max_jump_m.push_back(r.max_jump_height_m);
    for (auto& line : sample_.line_energy_kj) line.push_back(kNaN);
    for (const LineCrossing& c : out.line_crossings)
      sample_.line_energy_kj[static_cast<std::size_t>(c.line)].back() = c.energy_J() / 1e3;
  }

 private:
  Sample& sample_;
};

Sample RunSample(const Scene& scene, const ReleaseSpec& release, const SelfCheckOptions& options,
                 long stride) {
  EnsembleOptions run;
  run.threads = options.threads;
  run.stride = stride;
  run.end_rock = stride * options.rocks;
  run.evaluation_lines = options.evaluation_lines;
  Sample sample;
  const std::size_t lines = options.evaluation_lines ? options.evaluation_lines->size() : 0;
  SampleSink sink(sample, lines);
  RunEnsemble(scene, release, run, &sink);
  return sample;
}

// A statistic of a sample of per-rock values, evaluated on the rocks `pick` (indices, repeats
// allowed).
using Statistic = std::function<double(const std::vector<double>&)>;

std::vector<double> Pick(const std::vector<double>& values, const std::vector<std::size_t>& pick) {
  std::vector<double> out;
  out.reserve(pick.size());
  for (std::size_t i : pick) out.push_back(values[i]);
  return out;
}

SelfCheckStatistic Compare(const std::string& name, const std::string& unit,
                           const std::vector<double>& as_run, const std::vector<double>& refined,
                           const Statistic& statistic, const SelfCheckOptions& options) {
  SelfCheckStatistic s;
  s.name = name;
  s.unit = unit;
  s.as_run = statistic(as_run);
  s.refined = statistic(refined);
  s.difference = s.as_run - s.refined;
  // Paired bootstrap over the rocks: the same resampled rocks in both runs.
  std::mt19937_64 random(20261126);
  const std::size_t n = as_run.size();
  std::vector<std::size_t> pick(n);
  double sum = 0, sum2 = 0;
  int used = 0;
  for (int b = 0; b < options.bootstrap_resamples; ++b) {
    for (std::size_t& i : pick) i = static_cast<std::size_t>(random() % n);
    const double d = statistic(Pick(as_run, pick)) - statistic(Pick(refined, pick));
    if (!std::isfinite(d)) continue;
    sum += d;
    sum2 += d * d;
    ++used;
  }
  s.standard_error =
      used > 1 ? std::sqrt(std::max(0.0, (sum2 - sum * sum / used) / (used - 1))) : kNaN;
  return s;
}

// z with P(|Z| > z) = p for a standard normal Z: the quantile at 1 - p/2 (Boost.Math, from the
// upper tail so that a small p keeps its digits).
double TwoSidedNormalQuantile(double p) {
  return boost::math::quantile(boost::math::complement(boost::math::normal(), p / 2));
}

Statistic Percentile(double p) {
  return [p](const std::vector<double>& v) { return NearestRankPercentile(v, p); };
}

std::string Number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

}  // namespace

bool SelfCheckOptions::IsValid(std::string* why) const {
  std::ostringstream msg;
  if (rocks < 2)
    msg << "self_check = " << rocks << ": at least 2 rocks are needed for a standard error";
  else if (dt_divisor < 2)
    msg << "dt_divisor = " << dt_divisor << " violates dt_divisor >= 2";
  else if (!(refined_tolerance_m_s > 0))
    msg << "refined_tolerance_m_s = " << refined_tolerance_m_s << " violates > 0";
  else if (bootstrap_resamples < 10)
    msg << "bootstrap_resamples = " << bootstrap_resamples << " violates >= 10";
  else if (!(false_alarm_rate > 0 && false_alarm_rate < 1))
    msg << "false_alarm_rate = " << false_alarm_rate << " violates 0 < false_alarm_rate < 1";
  if (why) *why = msg.str();
  return msg.str().empty();
}

std::string SelfCheckReport::Verdict() const {
  const std::string steps = std::to_string(rocks) + " rocks at dt " + Number(dt_s) + " s and " +
                            Number(refined_dt_s) + " s";
  const SelfCheckStatistic* worst = nullptr;
  for (const SelfCheckStatistic& s : statistics)
    if (s.significant && (!worst || std::abs(s.difference) / s.standard_error >
                                        std::abs(worst->difference) / worst->standard_error))
      worst = &s;
  if (!worst) return "converged within the sampling noise (" + steps + ")";
  return "dt bias of " + Number(worst->difference) + " " + worst->unit + " (standard error " +
         Number(worst->standard_error) + ") in the " + worst->name + " (" + steps +
         "): use --preset accurate";
}

std::string SelfCheckReport::BriefReport() const {
  std::ostringstream out;
  out << "Self-check: " << Verdict() << "\n";
  char line[200];
  for (const SelfCheckStatistic& s : statistics) {
    std::snprintf(line, sizeof line, "  %-34s %10.4g %10.4g %+10.3g +- %-9.3g %s%s\n",
                  s.name.c_str(), s.as_run, s.refined, s.difference, s.standard_error,
                  s.unit.c_str(), s.significant ? "  *" : "");
    out << line;
  }
  return out.str();
}

SelfCheckReport RunSelfCheck(Scene& scene, const ReleaseSpec& release,
                             const SelfCheckOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("RunSelfCheck: " + why);
  if (options.rocks > release.total_rocks())
    throw std::invalid_argument("RunSelfCheck: " + std::to_string(options.rocks) +
                                " rocks asked for, the release has " +
                                std::to_string(release.total_rocks()));
  const auto t0 = std::chrono::steady_clock::now();
  const long stride = release.total_rocks() / options.rocks;
  const SolverOptions as_run = scene.options;
  SelfCheckReport report;
  report.rocks = options.rocks;
  report.dt_s = as_run.dt_s;
  report.tolerance_m_s = as_run.tolerance_m_s;
  const Sample a = RunSample(scene, release, options, stride);
  // The refined run, with the scene's options restored however it ends.
  struct Restore {
    Scene& scene;
    SolverOptions options;
    ~Restore() { scene.options = options; }
  } restore{scene, as_run};
  scene.options.dt_s = as_run.dt_s / options.dt_divisor;
  scene.options.tolerance_m_s = std::min(as_run.tolerance_m_s, options.refined_tolerance_m_s);
  scene.options.max_iterations = std::max(as_run.max_iterations, 1000);
  report.refined_dt_s = scene.options.dt_s;
  report.refined_tolerance_m_s = scene.options.tolerance_m_s;
  const Sample b = RunSample(scene, release, options, stride);

  auto& st = report.statistics;
  st.push_back(Compare("run-out median", "m", a.runout_m, b.runout_m, Percentile(50), options));
  st.push_back(Compare("run-out p95", "m", a.runout_m, b.runout_m, Percentile(95), options));
  st.push_back(Compare("largest speed p95", "m/s", a.max_speed_m_s, b.max_speed_m_s,
                       Percentile(95), options));
  st.push_back(Compare("largest kinetic energy p95", "kJ", a.max_energy_kj, b.max_energy_kj,
                       Percentile(95), options));
  st.push_back(Compare("largest jump height p95", "m", a.max_jump_m, b.max_jump_m,
                       Percentile(95), options));
  for (std::size_t k = 0; k < a.line_energy_kj.size(); ++k) {
    const std::string& name = (*options.evaluation_lines)[k].name;
    const Statistic passing = [](const std::vector<double>& v) {
      return static_cast<double>(std::count_if(v.begin(), v.end(),
                                                [](double e) { return std::isfinite(e); })) /
             static_cast<double>(v.size());
    };
    st.push_back(Compare("line " + name + " passing fraction", "", a.line_energy_kj[k],
                         b.line_energy_kj[k], passing, options));
    st.push_back(Compare("line " + name + " energy p95", "kJ", a.line_energy_kj[k],
                         b.line_energy_kj[k], Percentile(95), options));
  }
  report.threshold =
      TwoSidedNormalQuantile(options.false_alarm_rate / static_cast<double>(st.size()));
  for (SelfCheckStatistic& s : st)
    s.significant = std::isfinite(s.difference) && std::isfinite(s.standard_error) &&
                    std::abs(s.difference) > report.threshold * s.standard_error;
  report.converged = std::none_of(st.begin(), st.end(),
                                  [](const SelfCheckStatistic& s) { return s.significant; });
  report.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return report;
}

}  // namespace talus::ensemble
