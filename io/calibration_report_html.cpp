#include "io/calibration_report_html.hpp"

#include <algorithm>
#include <cmath>

#include "calibration/roughness.hpp"
#include "io/calibration_plots.hpp"
#include "io/html_page.hpp"
#include "io/svg_plot.hpp"

namespace talus::io {
namespace {

using html::Cell;
using html::Json;
using html::Number;
using html::NumberOf;
using html::UnitSuffix;
using svg::Add;
using svg::Escape;

// "lo &ndash; hi" of a two-number array, or "&ndash;".
std::string Interval(const Json& pair) {
  if (!pair.is_array() || pair.size() != 2) return "&ndash;";
  return Number(NumberOf(pair[0])) + " &ndash; " + Number(NumberOf(pair[1]));
}

std::string Head(const Json& c) {
  std::string note = "Talus " + Cell(c["version"]) + ", event " + Cell(c["event"]) +
                     ", inputs hash (SHA-256) " + Cell(c["inputs_sha256"]) + "; " +
                     Cell(c["algorithm"]) + ", " + Cell(c["evaluations"]) +
                     " evaluations, ended by " + Cell(c["termination"]) +
                     ". Everything here is also in calibration.json, history.csv and "
                     "ground_table.toml next to this file (docs/calibration.md).";
  return html::Begin("Talus calibration: " + c.value("calibration_file", std::string()), note) +
         html::WarningsOrNone(c["warnings"]);
}

// Why a fitted value is not supported: unidentified, at a bound ("" when it is).
std::string Doubt(const Json& p) {
  std::string why;
  if (p["identified"].is_boolean() && !p["identified"].get<bool>()) {
    why = "unidentified";
    // The rocks-per-run rule (docs/calibration.md, "How many rocks per run").
    const Json& profile = p.contains("profile") ? p["profile"] : Json();
    const double rocks =
        profile.is_object() ? NumberOf(profile.value("rocks_to_identify", Json())) : std::nan("");
    if (std::isfinite(rocks) && rocks > calibration::kMostRocksPerRun)
      why += " (no practical number of rocks per run would identify it)";
    else if (std::isfinite(rocks))
      why += " (about " + Number(std::max(2.0, std::ceil(rocks))) +
             " rocks per run would identify it" +
             (profile.value("within_noise", false) ? " if its profile's range is real, not noise"
                                                   : "") +
             ")";
  }
  const double u = NumberOf(p["final_unit_coordinate"]);
  if (std::isfinite(u) && (u <= 1e-3 || u >= 1 - 1e-3))
    why += std::string(why.empty() ? "" : "; ") + "at its " + (u <= 1e-3 ? "lower" : "upper") +
           " bound";
  return why;
}

std::string ParametersSection(const Json& c) {
  std::vector<std::vector<std::string>> rows;
  for (const Json& p : c["parameters"]) {
    const Json& interval = p.contains("combined_interval")    ? p["combined_interval"]
                           : p.contains("bootstrap_interval") ? p["bootstrap_interval"]
                                                              : Json();
    const Json& error = p.contains("combined_standard_error") ? p["combined_standard_error"]
                                                              : p.value("standard_error", Json());
    rows.push_back({Escape(p.value("name", std::string())) + UnitSuffix(p.value("unit", "")),
                    Number(NumberOf(p["lower"])) + " &ndash; " + Number(NumberOf(p["upper"])),
                    Number(NumberOf(p["initial"])), Number(NumberOf(p["final"])),
                    Number(NumberOf(error)), Interval(interval), Cell(p["identified"]),
                    Escape(Doubt(p))});
  }
  return "<h2>Fitted parameters</h2>\n" +
         html::Table({"parameter (unit)", "range", "initial", "fitted", "standard error",
                      "interval", "identified", "not supported because"},
                     rows) +
         "<p class=\"note\">Standard error: the sandwich covariance's, combined with the seed "
         "refits' spread when they ran; interval: the seed refits' combined interval, else the "
         "bootstrap's, when they ran. An unidentified parameter's value is where the fit left it "
         "(its profile is flat): ground_table.toml marks it.</p>\n";
}

std::string ObjectiveSection(const Json& c) {
  std::vector<std::vector<std::string>> rows;
  for (const Json& k : c["kinds"])
    rows.push_back(
        {Escape(html::HumanLabel(k.value("kind", std::string()))) + UnitSuffix(k.value("unit", "")),
         Number(NumberOf(k["weight"])), Number(NumberOf(k["score_before"])),
         Number(NumberOf(k["score_after"])), Cell(k["scored_after"])});
  std::string out = "<h2>Objective</h2>\n";
  Add(out, "<p>Objective ", Number(NumberOf(c["objective"]["before"])), " before, ",
      Number(NumberOf(c["objective"]["after"])), " after the fit.</p>\n");
  out +=
      html::Table({"kind (unit)", "weight", "mean CRPS before", "mean CRPS after", "scored"}, rows);
  return out;
}

std::string PlotsSection(const Json& c, const CalibrationReportInput& input) {
  std::string out = "<h2>Convergence</h2>\n" + html::Plots({input.convergence_svg});
  std::vector<std::string> profiles;
  for (const Json& p : c["parameters"]) {
    if (!p.contains("profile") || !p["profile"].is_object()) continue;
    std::vector<double> values, objective;
    for (const Json& v : p["profile"]["values"]) values.push_back(NumberOf(v));
    for (const Json& v : p["profile"]["objective"]) objective.push_back(NumberOf(v));
    profiles.push_back(ProfileSvg(p.value("name", std::string()), p.value("unit", ""), values,
                                  objective, NumberOf(p["final"]),
                                  p["identified"].is_boolean() && p["identified"].get<bool>()));
  }
  if (!profiles.empty()) out += "<h2>Profiles</h2>\n" + html::Plots(profiles);
  if (!input.observed_simulated.empty())
    out += "<h2>Observed and simulated</h2>\n" + html::Plots(input.observed_simulated);
  return out;
}

// Per kind: the held-out CRPS with the fitted and with the reference parameters, and the skill.
std::string HeldOutKinds(const Json& kinds) {
  std::vector<std::vector<std::string>> rows;
  for (const Json& k : kinds) {
    const double fitted = NumberOf(k["crps_fitted"]), reference = NumberOf(k["crps_reference"]);
    rows.push_back(
        {Escape(html::HumanLabel(k.value("kind", std::string()))) + UnitSuffix(k.value("unit", "")),
         Cell(k["scored"]), Number(fitted), Number(reference),
         Number(reference > 0 ? 1 - fitted / reference : NAN, "%.3f")});
  }
  return html::Table(
      {"kind (unit)", "scored", "mean CRPS, fitted", "mean CRPS, reference", "skill"}, rows);
}

std::string HeldOutSection(const Json& c) {
  std::string out;
  if (c["holdout"].is_object()) {
    Add(out, "<h2>Held-out runs</h2>\n<p>Runs left out of the fit: ", Cell(c["holdout"]["runs"]),
        ".</p>\n", HeldOutKinds(c["holdout"]["kinds"]),
        html::BlockBiasTable(c["holdout"].value("blocks", Json())));
  }
  if (c["cross_validation"].is_object()) {
    std::vector<std::vector<std::string>> rows;
    int fold = 0;
    for (const Json& f : c["cross_validation"]["folds"])
      rows.push_back({std::to_string(++fold), Cell(f["runs"]), Number(NumberOf(f["objective"])),
                      Cell(f["evaluations"]), Cell(f["termination"]), Cell(f["fitted"])});
    out += "<h2>Cross-validation</h2>\n" +
           html::Table({"fold", "held-out runs", "objective of its fit", "evaluations", "ended by",
                        "fitted values"},
                       rows) +
           "<p>Over every fold's held-out runs:</p>\n" +
           HeldOutKinds(c["cross_validation"]["kinds"]) +
           html::BlockBiasTable(c["cross_validation"].value("blocks", Json()));
  }
  const bool held_out = !out.empty();
  const std::string fitted = html::BlockBiasTable(c.value("fitted_runs_blocks", Json()));
  if (!fitted.empty()) out += "<h2>Bias per block, fitted runs</h2>\n" + fitted;
  if (held_out)
    out +=
        "<p class=\"note\">Skill = 1 - fitted / reference: below 0 the fitted parameters predict "
        "runs they were not fitted to worse than the reference does.</p>\n";
  return out;
}

std::string WhatRanSection(const Json& c) {
  std::string out = "<h2>What ran</h2>\n";
  out += html::KeyValueTable(c, {"version", "warnings", "parameters", "kinds", "starts",
                                 "not_scored", "message", "fitted_runs_blocks", "inputs_sha256",
                                 "holdout", "cross_validation", "roughness", "uncertainty"});
  out += "<h3>Timings</h3>\n" + html::KeyValueTable(c["timings"]);
  return out;
}

}  // namespace

std::string CalibrationReportHtml(const CalibrationReportInput& input) {
  const Json c = Json::parse(input.calibration_json);
  return Head(c) + ParametersSection(c) + ObjectiveSection(c) + PlotsSection(c, input) +
         HeldOutSection(c) + WhatRanSection(c) + html::End();
}

}  // namespace talus::io
