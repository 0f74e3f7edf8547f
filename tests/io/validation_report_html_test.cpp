// report.html of talus validate (io/validation_report_html.hpp), from a report built by hand.

#include "io/validation_report_html.hpp"

#include <gtest/gtest.h>

#include <string>

namespace talus::io {
namespace {

fieldobs::ValidationReport Report() {
  fieldobs::ValidationReport r;
  fieldobs::ObservationScore s;
  s.kind = std::string("runout");
  s.unit = std::string("m");
  s.run = std::string("r<1>");
  s.observed = 100;
  s.scored = true;
  s.members = 6;
  s.score = 3.5;
  s.pit = 0.25;
  s.mean = s.median = 104;
  s.q05 = 99;
  s.q95 = 109;
  r.observations = {s};
  s.run = std::string("r2");
  s.observed = 120;
  r.observations.push_back(s);
  fieldobs::KindSummary runout;
  runout.kind = std::string("runout");
  runout.unit = std::string("m");
  runout.observations = 2;
  runout.scored = 2;
  runout.mean_score = 3.5;
  runout.pit.counts = {1, 1};
  r.kinds = {runout};
  return r;
}

// scores.json with `warnings` (a JSON array).
std::string Scores(const std::string& warnings) {
  std::string scores = R"({"talus_version": "9.9", "event": "ev.toml", "scene": "scene.toml",
  "inputs_sha256": "abc", "rocks_per_run": 6, "runs": 2, "seed": 3,
  "reference": {"parameters": "none", "simulated": false, "note": ""},
  "ends": {"rest": 10, "left_domain": 2, "max_time": 0, "failed": 0},
  "observations": 2, "observations_scored": 2, "not_scored": [],
  "overall": {"skill_vs_reference": null, "skill_vs_climatology": 0.25},
  "kinds": {"runout": {"unit": "m", "score": "crps", "observations": 2, "scored": 2,
    "mean_score": 3.5, "mean_reference_score": null, "mean_climatology_score": 4.2,
    "skill_vs_reference": null, "skill_vs_climatology": 0.1667, "inside_90_fraction": 0.5,
    "mean_bias": 4, "mean_sd": 3, "pit": {"counts": [1, 1], "p_value": 0.5}}},
  "blocks": [], "start_ground_mismatch": [], "wall_time_s": 12.5, "threads": 7,
  "warnings": )";
  scores += warnings;  // appended (GCC 12 warns wrongly about std::string operator+ here)
  scores += "}";
  return scores;
}

TEST(ValidationReportHtml, ShowsWarningsScoresWithUnitsPlotsAndOneRowPerObservation) {
  const fieldobs::ValidationReport report = Report();
  const std::string html =
      ValidationReportHtml({Scores(R"(["2 of 12 rocks left the DEM"])"), &report, ""});
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("<h1>Talus validation: ev.toml</h1>"), std::string::npos);
  // Warnings first, before the scores.
  const auto warnings = html.find("<li>2 of 12 rocks left the DEM</li>");
  ASSERT_NE(warnings, std::string::npos);
  EXPECT_LT(warnings, html.find("Scores per kind"));
  // A kind's row: its human label with its unit, its score's name, the numbers.
  EXPECT_NE(html.find("<th>run-out (m)</th><td>2</td><td>2</td><td>CRPS</td><td>3.5</td>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<td>50 %</td>"), std::string::npos);  // inside the 5-95 % band
  // The plots inline: one observed-vs-simulated panel and one PIT histogram.
  EXPECT_NE(html.find(">run-out: simulated against observed</text>"), std::string::npos);
  EXPECT_NE(html.find("PIT: run-out (2 observations)"), std::string::npos);
  // One row per observation, with its run escaped.
  EXPECT_NE(html.find("<th>r&lt;1&gt;</th><td>run-out (m)</td><td>100</td><td>104</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<th>r2</th>"), std::string::npos);
  EXPECT_NE(html.find("<th>left the DEM</th><td>2</td>"), std::string::npos);
  // No raw keys, no timings, no script; no deposits map without deposits.
  EXPECT_EQ(html.find("rocks_per_run"), std::string::npos);
  EXPECT_EQ(html.find("12.5"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("<img"), std::string::npos);
}

TEST(ValidationReportHtml, SaysThereAreNoWarningsWhenThereAreNone) {
  const fieldobs::ValidationReport report = Report();
  const std::string html = ValidationReportHtml({Scores("[]"), &report, ""});
  EXPECT_NE(html.find("<h2>Warnings</h2>\n<p>None.</p>"), std::string::npos) << html;
}

// Per block, its mean bias with the standard error over its runs; no section without blocks.
TEST(ValidationReportHtml, ShowsTheBiasPerBlockWithItsStandardError) {
  const fieldobs::ValidationReport report = Report();
  std::string scores = Scores("[]");
  const std::string none = ValidationReportHtml({scores, &report, ""});
  EXPECT_EQ(none.find("Bias per block"), std::string::npos);
  const std::string empty_blocks = R"("blocks": [])";
  scores.replace(
      scores.find(empty_blocks), empty_blocks.size(),
      R"("blocks": [{"block": "plate", "kind": "runout", "unit": "m", "scored": 4, "runs": 4,
                     "mean_bias": -19.1, "bias_standard_error": 12.4, "mean_score": 17}])");
  const std::string html = ValidationReportHtml({scores, &report, ""});
  EXPECT_NE(html.find("<h2>Bias per block</h2>"), std::string::npos);
  EXPECT_NE(html.find("<th>plate</th><td>run-out (m)</td><td>4</td><td>4</td><td>-19.1</td>"
                      "<td>12.4</td>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("12.4"), std::string::npos);
}

}  // namespace
}  // namespace talus::io
