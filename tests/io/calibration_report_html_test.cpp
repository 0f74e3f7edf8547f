// report.html of talus calibrate (io/calibration_report_html.hpp), from a calibration.json
// written by hand.

#include "io/calibration_report_html.hpp"

#include <gtest/gtest.h>

#include <string>

namespace talus::io {
namespace {

const char* kCalibration = R"({"version": "9.9", "calibration_file": "cal.toml",
  "event": "event.toml", "inputs": ["a"], "inputs_sha256": "abc", "runs": 4, "rocks_per_run": 4,
  "seed": 3, "solver": {"tolerance_m_s": 1e-7}, "threads": 2, "algorithm": "bobyqa",
  "termination": "max_evaluations", "message": "m",
  "parameters": [
    {"name": "medium.mu_min", "unit": "1", "lower": 0.1, "upper": 0.9, "log": false,
     "initial": 0.3, "final": 0.42, "final_unit_coordinate": 0.4, "identified": true,
     "profile": {"u": [0, 0.5, 1], "values": [0.1, 0.5, 0.9], "objective": [3, 2, 4]},
     "standard_error": 0.05},
    {"name": "medium.kappa", "unit": "1/m", "lower": 0.5, "upper": 20, "log": true,
     "initial": 2, "final": 20, "final_unit_coordinate": 1.0, "identified": false,
     "profile": {"u": [0, 0.5, 1], "values": [0.5, 3.2, 20], "objective": [2.1, 2.0, 2.05],
                 "rocks_to_identify": 46.2, "within_noise": false},
     "standard_error": null}],
  "objective": {"before": 3.35, "after": 2.5},
  "kinds": [{"kind": "runout", "unit": "m", "weight": 1, "scale": 1, "score_before": 3.35,
             "score_after": 2.5, "scored_before": 4, "scored_after": 4}],
  "evaluations": 6, "timings": {"calibration_s": 1.5, "total_s": 2.5},
  "uncertainty": null, "not_scored": [],
  "warnings": ["medium.kappa is unidentified"],
  "holdout": {"runs": ["r2"], "kinds": [{"kind": "runout", "unit": "m", "observations": 1,
              "scored": 1, "crps_fitted": 3.0, "crps_reference": 2.0}],
              "blocks": [{"block": "plate", "kind": "runout", "unit": "m", "scored": 4, "runs": 4,
                          "mean_bias": -19.1, "bias_standard_error": 12.4, "mean_score": 17}]},
  "cross_validation": {"folds": [{"runs": ["r1", "r3"], "objective": 2.2, "evaluations": 5,
                        "termination": "ftol", "fitted": [0.4, 19]}],
                       "kinds": [{"kind": "runout", "unit": "m", "scored": 2,
                                  "crps_fitted": 2.0, "crps_reference": 2.5}]},
  "roughness": null})";

TEST(CalibrationReportHtml, ShowsTheFitWithItsDoubtsPlotsHeldOutRunsAndFolds) {
  const std::string html =
      CalibrationReportHtml({kCalibration, "<svg id=\"convergence\"></svg>\n", {}});
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("<h1>Talus calibration: cal.toml</h1>"), std::string::npos);
  const auto warning = html.find("<li>medium.kappa is unidentified</li>");
  ASSERT_NE(warning, std::string::npos);
  EXPECT_LT(warning, html.find("Fitted parameters"));
  // The fitted table: unit, range, values, standard error, why a value is not supported.
  EXPECT_NE(html.find("<th>medium.mu_min</th><td>0.1 &ndash; 0.9</td><td>0.3</td><td>0.42</td>"
                      "<td>0.05</td>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<th>medium.kappa (1/m)</th>"), std::string::npos);
  // With what the rocks-per-run rule says (docs/calibration.md, "How many rocks per run").
  EXPECT_NE(html.find("<td>unidentified (about 47 rocks per run would identify it); at its upper "
                      "bound</td>"),
            std::string::npos)
      << html;
  std::string within = kCalibration;
  within.replace(within.find("\"within_noise\": false"), 21, "\"within_noise\": true ");
  EXPECT_NE(CalibrationReportHtml({within, "", {}})
                .find("<td>unidentified (about 47 rocks per run would identify it if its "
                      "profile's range is real, not noise); at its upper bound</td>"),
            std::string::npos);
  std::string beyond = kCalibration;
  beyond.replace(beyond.find("\"rocks_to_identify\": 46.2"), 25, "\"rocks_to_identify\": 3e9 ");
  EXPECT_NE(CalibrationReportHtml({beyond, "", {}})
                .find("<td>unidentified (no practical number of rocks per run would identify "
                      "it); at its upper bound</td>"),
            std::string::npos);
  // The convergence plot as given, and a profile per parameter from calibration.json.
  EXPECT_NE(html.find("<svg id=\"convergence\">"), std::string::npos);
  EXPECT_NE(html.find(">Profile of medium.mu_min</text>"), std::string::npos);
  EXPECT_NE(html.find(">Profile of medium.kappa (flat: unidentified)</text>"), std::string::npos);
  // Held out: skill 1 - 3 / 2 = -0.5; pooled over the folds 1 - 2 / 2.5 = 0.2.
  EXPECT_NE(html.find("<td>3</td><td>2</td><td>-0.500</td>"), std::string::npos);
  EXPECT_NE(html.find("<td>2</td><td>2.5</td><td>0.200</td>"), std::string::npos);
  EXPECT_NE(html.find("<th>1</th><td>r1, r3</td>"), std::string::npos);
  // The held-out runs' bias per block with its standard error.
  EXPECT_NE(html.find("<th>plate</th><td>run-out (m)</td><td>4</td><td>4</td><td>-19.1</td>"
                      "<td>12.4</td>"),
            std::string::npos)
      << html;
  EXPECT_EQ(html.find("rocks_per_run"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
}

}  // namespace
}  // namespace talus::io
