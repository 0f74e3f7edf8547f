#include "io/validation_report_html.hpp"

#include <cmath>
#include <map>
#include <vector>

#include "io/html_page.hpp"
#include "io/svg_plot.hpp"
#include "io/validation_outputs.hpp"

namespace talus::io {
namespace {

using html::Cell;
using html::Json;
using html::Number;
using html::NumberOf;
using html::UnitSuffix;
using svg::Add;
using svg::Escape;

std::string Percent(double fraction) {
  return std::isfinite(fraction) ? Number(100 * fraction, "%.0f") + " %" : "&ndash;";
}

// The head: event, scene, version and inputs hash; then the warnings.
std::string Head(const Json& scores) {
  const std::string event = scores.value("event", std::string());
  return html::Begin("Talus validation: " + event,
                     "Talus " + Cell(scores["talus_version"]) + ", scene " + Cell(scores["scene"]) +
                         ", inputs hash (SHA-256) " + Cell(scores["inputs_sha256"]) +
                         ". Everything here is also in scores.json and observations.csv next to "
                         "this file (docs/validation.md).") +
         html::WarningsOrNone(scores["warnings"]);
}

// "Scores per kind": one row per kind, with its unit, and the overall skills.
std::string ScoresSection(const Json& scores) {
  std::vector<std::vector<std::string>> rows;
  for (const auto& [kind, k] : scores["kinds"].items()) {
    const std::string unit = k.value("unit", std::string());
    rows.push_back({Escape(html::HumanLabel(kind)) + UnitSuffix(unit), Cell(k["observations"]),
                    Cell(k["scored"]), Escape(html::HumanLabel(k.value("score", std::string()))),
                    Number(NumberOf(k["mean_score"])), Number(NumberOf(k["mean_reference_score"])),
                    Number(NumberOf(k["mean_climatology_score"])),
                    Number(NumberOf(k["skill_vs_reference"]), "%.3f"),
                    Number(NumberOf(k["skill_vs_climatology"]), "%.3f"),
                    Percent(NumberOf(k["inside_90_fraction"])), Number(NumberOf(k["mean_bias"])),
                    Number(NumberOf(k["mean_sd"])),
                    k.contains("pit") ? Number(NumberOf(k["pit"]["p_value"]), "%.2g") : "&ndash;"});
  }
  std::string out = "<h2>Scores per kind</h2>\n";
  out += html::Table(
      {"kind (unit)", "observations", "scored", "score", "mean score", "reference's mean score",
       "climatology's mean score", "skill vs reference", "skill vs climatology",
       "inside the 5-95 % band", "mean bias", "mean spread (sd)", "PIT p-value"},
      rows);
  const Json& overall = scores["overall"];
  Add(out, "<p>Over the kinds: skill against the reference ",
      Number(NumberOf(overall["skill_vs_reference"]), "%.3f"), ", against climatology ",
      Number(NumberOf(overall["skill_vs_climatology"]), "%.3f"), ".</p>\n");
  out +=
      "<p class=\"note\">Scores are in the kind's unit, lower is better: the CRPS for scalars, "
      "the energy score for deposits. Skill = 1 - score / baseline's score: above 0 the "
      "parameters beat the baseline. Bias = simulated mean - observed. A calibrated spread puts "
      "90 % of the observations inside the simulated 5-95 % band and gives a flat PIT histogram "
      "(p-value of its chi-square test not small).</p>\n";
  if (scores.contains("reference") && scores["reference"].value("note", std::string()) != "")
    Add(out, "<p class=\"note\">Reference: ", Cell(scores["reference"]["note"]), ".</p>\n");
  return out;
}

std::string PlotsSection(const ValidationReportInput& input) {
  std::string out;
  const std::vector<std::string> scatter = ObservedVsSimulatedPanels(*input.report);
  const std::vector<std::string> pit = PitPanels(*input.report);
  if (!scatter.empty()) out += "<h2>Observed and simulated</h2>\n" + html::Plots(scatter);
  if (!pit.empty()) out += "<h2>PIT histograms</h2>\n" + html::Plots(pit);
  if (!input.deposits_png.empty())
    out += "<h2>Deposits</h2>\n" +
           html::PngFigure(input.deposits_png, "deposits",
                           "Observed (red) and simulated (blue) rest positions, and where "
                           "simulated rocks left the DEM (grey) (deposits.png)");
  return out;
}

// "Per run": one row per observation, grouped by run in the order the runs first appear.
std::string PerRunSection(const fieldobs::ValidationReport& report) {
  std::vector<std::string> runs;
  std::map<std::string, std::vector<const fieldobs::ObservationScore*>> by_run;
  for (const fieldobs::ObservationScore& s : report.observations) {
    if (!by_run.count(s.run)) runs.push_back(s.run);
    by_run[s.run].push_back(&s);
  }
  std::vector<std::vector<std::string>> rows;
  for (const std::string& run : runs)
    for (const fieldobs::ObservationScore* s : by_run[run]) {
      const bool deposit = s->kind == "deposit";
      rows.push_back({Escape(run.empty() ? "(all)" : run),
                      Escape(html::HumanLabel(s->kind)) + UnitSuffix(s->unit),
                      deposit ? Number(s->observed_xy_m.x(), "%.1f") + ", " +
                                    Number(s->observed_xy_m.y(), "%.1f")
                              : Number(s->observed),
                      (deposit ? "distance " : "") + Number(s->median),
                      (deposit ? "distance " : "") + Number(s->q05) + " &ndash; " + Number(s->q95),
                      Number(s->score), Number(s->pit, "%.2f"),
                      s->scored ? std::to_string(s->members) : Escape(s->not_scored)});
    }
  if (rows.empty()) return "";
  return "<h2>Per run</h2>\n" +
         html::Table({"run", "kind (unit)", "observed", "simulated median", "simulated 5-95 %",
                      "score", "PIT", "simulated values (or why not scored)"},
                     rows) +
         "<p class=\"note\">Quantiles are type 7 (linear between order statistics) over the run's "
         "simulated rocks, as in scores.json and observations.csv; for a deposit, of the "
         "distances (m) from the observed rest position to the simulated ones.</p>\n";
}

// "Bias per block": what a ground table cannot remove and a block's shape can, with the standard
// error over the block's runs to judge it by. Absent without blocks.
std::string BlocksSection(const Json& scores) {
  const std::string table = html::BlockBiasTable(scores.value("blocks", Json()));
  return table.empty() ? "" : "<h2>Bias per block</h2>\n" + table;
}

// How the rocks ended and what ran.
std::string RunSection(const Json& scores) {
  std::string out = "<h2>How the rocks ended</h2>\n<table>\n";
  for (const auto& [ending, n] : scores["ends"].items())
    Add(out, "<tr><th>", Escape(html::HumanLabel(ending)), "</th><td>", Cell(n), "</td></tr>\n");
  out += "</table>\n<h2>What ran</h2>\n";
  out += html::KeyValueTable(
      scores, {"talus_version", "inputs_sha256", "event", "scene", "warnings", "kinds", "blocks",
               "ends", "overall", "wall_time_s", "threads", "start_ground_mismatch"});
  return out;
}

}  // namespace

std::string ValidationReportHtml(const ValidationReportInput& input) {
  const Json scores = Json::parse(input.scores_json);
  return Head(scores) + ScoresSection(scores) + PlotsSection(input) + PerRunSection(*input.report) +
         BlocksSection(scores) + RunSection(scores) + html::End();
}

}  // namespace talus::io
