#include "io/validation_outputs.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "common/format.hpp"
#include "ensemble/run_warnings.hpp"
#include "io/html_page.hpp"
#include "io/quicklook.hpp"
#include "io/rocks_csv.hpp"
#include "io/svg_plot.hpp"

namespace talus::io {
namespace {

// NaN and infinities are null in JSON.
nlohmann::ordered_json Num(double v) {
  return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

// "%.10g", or an empty field for NaN (a value that does not exist).
std::string Csv(double v) { return FormatOrMissing(v, "%.10g", ""); }

std::string Fmt(double v, const char* format = "%.3g") { return FormatDouble(v, format); }

}  // namespace

nlohmann::ordered_json BlockBiasJson(const std::vector<fieldobs::BlockBias>& biases) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const fieldobs::BlockBias& b : biases)
    out.push_back({{"block", b.block},
                   {"kind", b.kind},
                   {"unit", b.unit},
                   {"scored", b.scored},
                   {"runs", b.runs},
                   {"mean_bias", Num(b.mean_bias)},
                   {"bias_standard_error", Num(b.bias_standard_error)},
                   {"mean_score", Num(b.mean_score)}});
  return out;
}

std::vector<std::string> ValidationWarnings(const EventFile& event, const ValidationRun& run) {
  std::vector<std::string> warnings = event.scene.warnings;
  // The endings censor where rocks end (run-outs, deposits, reach), not a single impact's
  // first contact: an event of impacts alone (short runs by design) is not warned about them.
  bool endings_matter = !event.observations.deposits.empty();
  for (const auto& o : event.observations.scalars)
    endings_matter =
        endings_matter || std::string(fieldobs::ToString(o.quantity)).rfind("impact_", 0) != 0;
  if (endings_matter)
    for (const std::string& w : ensemble::RunWarnings(run.ensemble, event.scene.scene.options))
      warnings.push_back(w);
  return warnings;
}

std::string ScoresJson(const EventFile& event, const fieldobs::ValidationReport& report,
                       const ValidationRun& run) {
  nlohmann::ordered_json j;
  j["talus_version"] = run.version;
  j["event"] = event.path;
  j["scene"] = event.scene.path;
  j["inputs"] = event.inputs;
  j["inputs_sha256"] = event.inputs_hash;
  j["rocks_per_run"] = run.rocks_per_run;
  j["runs"] = event.scene.release.release_count();
  j["seed"] = run.seed;
  j["reference"] = {{"parameters", event.reference},
                    {"simulated", run.reference_run},
                    {"note", run.reference_run || event.reference == "none"
                                 ? ""
                                 : "the scene's ground table is the reference: skill 0"}};
  j["ends"] = {{"rest", run.ensemble.count(EndReason::kRest)},
               {"left_domain", run.ensemble.count(EndReason::kLeftDomain)},
               {"max_time", run.ensemble.count(EndReason::kMaxTime)},
               {"failed", run.ensemble.count(EndReason::kFailed)}};
  if (!event.scene.scene.barriers.empty())
    j["ends"]["barrier"] = run.ensemble.count(EndReason::kBarrier);
  j["observations"] = report.observations.size();
  j["observations_scored"] = report.observations_scored;
  j["not_scored"] = event.not_scored;  // observed values without a simulated counterpart
  j["overall"] = {{"skill_vs_reference", Num(report.skill_vs_reference)},
                  {"skill_vs_climatology", Num(report.skill_vs_climatology)}};
  nlohmann::ordered_json kinds = nlohmann::ordered_json::object();
  for (const fieldobs::KindSummary& k : report.kinds) {
    nlohmann::ordered_json kind;
    kind["unit"] = k.unit;
    kind["score"] = k.kind == "deposit" ? "energy_score" : "crps";
    kind["observations"] = k.observations;
    kind["scored"] = k.scored;
    kind["mean_score"] = Num(k.mean_score);
    kind["mean_reference_score"] = Num(k.mean_reference_score);
    kind["mean_climatology_score"] = Num(k.mean_climatology_score);
    kind["skill_vs_reference"] = Num(k.skill_vs_reference);
    kind["skill_vs_climatology"] = Num(k.skill_vs_climatology);
    kind["inside_90_fraction"] = Num(k.inside_90_fraction);
    kind["mean_bias"] = Num(k.mean_bias);
    kind["mean_sd"] = Num(k.mean_sd);
    if (!k.pit.counts.empty())
      kind["pit"] = {{"counts", k.pit.counts},
                     {"chi_square", Num(k.pit.chi_square)},
                     {"degrees_of_freedom", k.pit.degrees_of_freedom},
                     {"p_value", Num(k.pit.p_value)}};
    kinds[k.kind] = kind;
  }
  j["kinds"] = kinds;
  j["blocks"] = BlockBiasJson(fieldobs::BiasByBlock(report.observations, event.scene.release));
  j["warnings"] = ValidationWarnings(event, run);
  nlohmann::ordered_json mismatches = nlohmann::ordered_json::array();
  for (const GroundMismatch& m : event.scene.ground_mismatches)
    mismatches.push_back({{"run", m.run},
                          {"where", m.where},
                          {"dem_z_m", m.dem_z_m},
                          {"surveyed_ground_z_m", m.surveyed_z_m}});
  j["start_ground_mismatch"] = mismatches;
  j["wall_time_s"] = run.wall_time_s;
  j["threads"] = run.threads;
  return j.dump(2) + "\n";
}

std::string ObservationsCsv(const fieldobs::ValidationReport& report) {
  std::string out =
      "kind,run,unit,observed,observed_x_m,observed_y_m,scored,members,score,pit,mean,median,sd,"
      "q05,q95,inside_90,bias,reference_score,climatology_score,source,note\n";
  for (const fieldobs::ObservationScore& s : report.observations) {
    out += CsvField(s.kind) + "," + CsvField(s.run) + "," + s.unit + "," + Csv(s.observed) + "," +
           Csv(s.observed_xy_m.x()) + "," + Csv(s.observed_xy_m.y()) + "," +
           (s.scored ? "1" : "0") + "," + std::to_string(s.members) + "," + Csv(s.score) + "," +
           Csv(s.pit) + "," + Csv(s.mean) + "," + Csv(s.median) + "," + Csv(s.sd) + "," +
           Csv(s.q05) + "," + Csv(s.q95) + "," + (s.scored ? (s.inside_90 ? "1" : "0") : "") + "," +
           Csv(s.bias) + "," + Csv(s.reference_score) + "," + Csv(s.climatology_score) + "," +
           CsvField(s.where) + "," + CsvField(s.not_scored) + "\n";
  }
  return out;
}

namespace {

// "observed (m)", or "observed" for a dimensionless kind.
std::string WithUnit(const std::string& what, const std::string& unit) {
  return unit.empty() || unit == "1" ? what : what + " (" + unit + ")";
}

// One kind's scored observations: each at its observed value (x) with its simulated 5-95 % band
// (grey bar, the run's id as its tooltip) and median (dot), and the 1:1 line.
std::string ObservedVsSimulatedPanel(const fieldobs::KindSummary& kind,
                                     const std::vector<fieldobs::ObservationScore>& observations) {
  using svg::Add;
  using svg::F;
  std::vector<const fieldobs::ObservationScore*> obs;
  for (const auto& s : observations)
    if (s.kind == kind.kind && s.scored) obs.push_back(&s);
  double lo = INFINITY, hi = -INFINITY;
  for (const auto* s : obs)
    for (double v : {s->observed, s->q05, s->q95})
      if (std::isfinite(v)) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
  if (!std::isfinite(lo)) lo = hi = 0;
  svg::Pad(lo, hi);
  const svg::Axis x{lo, hi, svg::kLeft, svg::kWidth - svg::kRight};
  const svg::Axis y{lo, hi, svg::kHeight - svg::kBottom, svg::kTop};
  const std::string label = html::HumanLabel(kind.kind);
  std::string out =
      svg::Frame(label + ": simulated against observed", WithUnit("observed", kind.unit),
                 WithUnit("simulated", kind.unit), x, y);
  Add(out, "<line x1=\"", F(x(lo)), "\" y1=\"", F(y(lo)), "\" x2=\"", F(x(hi)), "\" y2=\"",
      F(y(hi)), "\" stroke=\"black\" stroke-dasharray=\"4 3\"/>\n");
  for (const auto* s : obs) {
    Add(out, "<line x1=\"", F(x(s->observed)), "\" x2=\"", F(x(s->observed)), "\" y1=\"",
        F(y(s->q05)), "\" y2=\"", F(y(s->q95)), "\" stroke=\"#bbbbbb\" stroke-width=\"4\"><title>",
        svg::Escape(s->run), "</title></line>\n");
    Add(out, "<circle cx=\"", F(x(s->observed)), "\" cy=\"", F(y(s->median)),
        "\" r=\"3\" fill=\"#1f5fbf\"><title>", svg::Escape(s->run), "</title></circle>\n");
  }
  Add(out, "<text x=\"", F(svg::kLeft + 6), "\" y=\"", F(svg::kTop + 14),
      "\">grey: simulated 5-95 %, dot: median, dashed: 1:1</text>\n<text x=\"", F(svg::kLeft + 6),
      "\" y=\"", F(svg::kTop + 28), "\">mean CRPS ", Fmt(kind.mean_score), " ",
      kind.unit == "1" ? "" : svg::Escape(kind.unit), "</text>\n");
  return out + "</svg>\n";
}

// One kind's PIT histogram: a calibrated ensemble gives bars as high as the dashed line.
std::string PitPanel(const fieldobs::KindSummary& kind) {
  using svg::Add;
  using svg::F;
  const fieldobs::PitHistogram& pit = kind.pit;
  int total = 0, most = 1;
  for (int c : pit.counts) {
    total += c;
    most = std::max(most, c);
  }
  const double expected = double(total) / double(pit.counts.size());
  const svg::Axis x{0, 1, svg::kLeft, svg::kWidth - svg::kRight};
  const svg::Axis y{0, std::max(double(most), 1.5 * expected), svg::kHeight - svg::kBottom,
                    svg::kTop};
  std::string out = svg::Frame(
      "PIT: " + html::HumanLabel(kind.kind) + " (" + std::to_string(total) + " observations)",
      "probability integral transform", "observations", x, y);
  const double width = 1.0 / double(pit.counts.size());
  for (std::size_t b = 0; b < pit.counts.size(); ++b)
    Add(out, "<rect x=\"", F(x(double(b) * width) + 1), "\" y=\"", F(y(pit.counts[b])),
        "\" width=\"", F(x(width) - x(0) - 2), "\" height=\"", F(y(0) - y(pit.counts[b])),
        "\" fill=\"#6a8fd0\"/>\n");
  Add(out, "<line x1=\"", F(x(0)), "\" x2=\"", F(x(1)), "\" y1=\"", F(y(expected)), "\" y2=\"",
      F(y(expected)), "\" stroke=\"black\" stroke-dasharray=\"4 3\"/>\n");
  Add(out, "<text x=\"", F(svg::kLeft + 6), "\" y=\"", F(svg::kTop + 14),
      "\">chi-square p = ", Fmt(pit.p_value, "%.2g"), "; dashed: flat (calibrated)</text>\n");
  return out + "</svg>\n";
}

}  // namespace

std::vector<std::string> ObservedVsSimulatedPanels(const fieldobs::ValidationReport& report) {
  std::vector<std::string> panels;
  for (const auto& k : report.kinds)
    if (k.kind != "deposit" && k.scored > 0)
      panels.push_back(ObservedVsSimulatedPanel(k, report.observations));
  return panels;
}

std::vector<std::string> PitPanels(const fieldobs::ValidationReport& report) {
  std::vector<std::string> panels;
  for (const auto& k : report.kinds)
    if (!k.pit.counts.empty()) panels.push_back(PitPanel(k));
  return panels;
}

std::string ObservedVsSimulatedSvg(const fieldobs::ValidationReport& report) {
  return svg::Stack(ObservedVsSimulatedPanels(report), 2, "no scalar observation was scored");
}

std::string PitSvg(const fieldobs::ValidationReport& report) {
  return svg::Stack(PitPanels(report), 3, "no PIT histogram (too few scalars)");
}

void WriteTextFile(const std::string& path, const std::string& text) {
  AtomicFile file(path);
  std::FILE* out = std::fopen(file.temp_path().c_str(), "w");
  if (!out) throw std::runtime_error("cannot create " + file.temp_path());
  const bool ok = std::fwrite(text.data(), 1, text.size(), out) == text.size();
  if (std::fclose(out) != 0 || !ok) throw std::runtime_error("cannot write " + path);
  file.Commit();
}

std::string DepositsPng(const EventFile& event, const fieldobs::EnsembleSamples& simulated) {
  std::vector<MapMarker> markers;
  // A rock that left the DEM did not come to rest there: its end is where it left, drawn apart.
  for (const Eigen::Vector2d& end : simulated.EndPositions("", false))
    markers.push_back({end, {40, 90, 220}, 1, "simulated rest position"});
  for (const Eigen::Vector2d& end : simulated.EndPositions("", true))
    markers.push_back({end, {150, 150, 150}, 1, "simulated rock leaving the DEM (where it left)"});
  for (const fieldobs::DepositObservation& d : event.observations.deposits)
    markers.push_back({d.xy_m, {215, 25, 28}, 3, "observed rest position"});
  return QuickLookPng(event.scene.scene.terrain.heights(), nullptr, {}, markers);
}

}  // namespace talus::io
