#include "io/report_html.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "common/error.hpp"
#include "io/rocks_csv.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

// A rocks.csv with the real header and the given runout values (other columns made up).
std::string RocksCsv(const std::vector<std::string>& runouts) {
  std::string text = std::string(RocksCsvWriter::Header()) + "\n";
  int rock = 0;
  for (const std::string& runout : runouts) {
    text += std::to_string(rock) + ",0,\"run, " + std::to_string(rock) + "\",1,rest,0,0,0," +
            runout + ",1,2,3.5,4000,0.5,6,0,\"a \"\"block\"\"\",100,0,0,0,30,hard,\n";
    ++rock;
  }
  return text;
}

// Every value a source emits, by column.
std::vector<std::vector<double>> Collect(const ColumnSource& source) {
  std::vector<std::vector<double>> out(kRockColumnCount);
  source([&](std::size_t column, double v) { out.at(column).push_back(v); });
  return out;
}

TEST(ReportHtml, ReadsTheRockColumnsByNameThroughQuotedFields) {
  const auto dir = testing::FreshDir("csv");
  testing::WriteText(dir / "rocks.csv", RocksCsv({"10", "20.5", "30"}));
  const ColumnSource rocks = RockColumns((dir / "rocks.csv").string());
  const auto columns = Collect(rocks);
  ASSERT_EQ(columns[kRunoutColumn].size(), 3u);
  EXPECT_DOUBLE_EQ(columns[kRunoutColumn][1], 20.5);
  EXPECT_DOUBLE_EQ(columns[kEnergyColumn][0], 4.0);  // 4000 J in kJ
  EXPECT_DOUBLE_EQ(columns[kSpeedColumn][2], 3.5);
  EXPECT_DOUBLE_EQ(columns[kJumpHeightColumn][0], 0.5);
  EXPECT_DOUBLE_EQ(columns[kTravelAngleColumn][0], 30);
  EXPECT_EQ(Collect(rocks), columns);  // read again, the same
}

TEST(ReportHtml, ABrokenRocksCsvIsAnErrorNamingTheLine) {
  const auto dir = testing::FreshDir("bad");
  testing::WriteText(dir / "rocks.csv", RocksCsv({"10", "abc"}));
  try {
    Collect(RockColumns((dir / "rocks.csv").string()));
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rocks.csv:3: column 'runout_m': 'abc'"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(RockColumns((dir / "missing.csv").string()), InputError);  // at once
}

// The rocks' statistics and histograms read back from rocks.csv in a budget far below the rocks'
// values (narrowed digit by digit, common/column_statistics.hpp) give the same page, byte for byte.
TEST(ReportHtml, TheSamePageInAnyMemoryBudget) {
  const auto dir = testing::FreshDir("budget");
  std::vector<std::string> runouts;
  for (int i = 0; i < 700; ++i)
    runouts.push_back(std::to_string(std::pow(1.013, i % 331) * (i % 7 == 0 ? 0.5 : 12.25)));
  runouts[17] = "";  // a rock without a runout
  testing::WriteText(dir / "rocks.csv", RocksCsv(runouts));
  RunReportInput input;
  input.summary_json = R"({"rocks": 700})";
  input.rocks = RockColumns((dir / "rocks.csv").string());
  const std::string page = RunReportHtml(input);
  EXPECT_NE(page.find("n = 699, median "), std::string::npos);
  input.statistics_budget_bytes = 64;
  EXPECT_EQ(RunReportHtml(input), page);
  input.statistics_budget_bytes = 8;
  EXPECT_EQ(RunReportHtml(input), page);
}

TEST(ReportHtml, HistogramCountsEveryValueOnce) {
  const std::string plot = HistogramSvg("Runout", "runout (m)", {1, 2, 2, 3, 10}, 10);
  EXPECT_NE(plot.find("<svg"), std::string::npos);
  EXPECT_NE(plot.find("n = 5, median 2, 95 % 10, largest 10"), std::string::npos) << plot;
  // Ten bars (one per bin) besides the frame's two rectangles.
  std::size_t rects = 0;
  for (std::size_t at = plot.find("<rect"); at != std::string::npos;
       at = plot.find("<rect", at + 1))
    ++rects;
  EXPECT_EQ(rects, 12u);
}

TEST(ReportHtml, ShowsTheSummaryWithoutTimingsAndEscapesText) {
  RunReportInput input;
  input.summary_json = R"({"talus_version": "9.9", "scene": "a<b>.toml", "rocks": 4,
      "ends": {"rest": 3, "left_domain": 1}, "raised_at_release": 0, "stayed_at_release": 1,
      "ground": {"hard": {"code": 6, "mu_min": 0.55}}, "solver": {"dt_s": 0.002},
      "threads": 7, "wall_time_s": 123.456, "trajectories_per_s": 0.0324})";
  input.rocks = [](const ColumnSink& emit) {
    for (double runout : {1, 2, 3, 4}) emit(kRunoutColumn, runout);
  };
  const std::string html = RunReportHtml(input);
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("a&lt;b&gt;.toml"), std::string::npos);
  EXPECT_EQ(html.find("a<b>"), std::string::npos);
  EXPECT_NE(html.find("75.0 %"), std::string::npos);  // 3 of 4 at rest
  EXPECT_NE(html.find("<th>hard</th><td>6</td><td>0.55</td>"), std::string::npos);
  // Nothing that differs between a run and the same run split into parts.
  EXPECT_EQ(html.find("123.456"), std::string::npos);
  EXPECT_EQ(html.find("wall_time"), std::string::npos);
  EXPECT_EQ(html.find("threads"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
}

// The evaluation lines' summary of summary.json as a table per line; energies in kJ.
TEST(ReportHtml, ShowsTheEvaluationLinesSummary) {
  RunReportInput input;
  input.summary_json = R"({"rocks": 4, "evaluation_lines": [{"name": "net <A>", "length_m": 12.5,
      "rocks": 4, "crossed": 3, "passing_probability": 0.75,
      "speed_m_s": {"mean": 10, "p50": 9, "p90": 12, "p95": 12, "p99": 12, "max": 12},
      "energy_J": {"mean": 15000, "p50": 14000, "p90": 21000, "p95": 21000, "p99": 21000,
                   "max": 21000},
      "com_height_m": {"mean": 1, "p50": 1, "p90": 1, "p95": 1, "p99": 1, "max": 1},
      "bounce_height_m": {"mean": null, "p50": null, "p90": null, "p95": null, "p99": null,
                          "max": null}}]})";
  const std::string html = RunReportHtml(input);
  EXPECT_NE(html.find("<h2>Evaluation lines</h2>"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>net &lt;A&gt;</th><td>12.5</td><td>4</td><td>3</td><td>75.0 %</td>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<th>kinetic energy (kJ)</th><td>15</td><td>14</td><td>21</td>"),
            std::string::npos);
  EXPECT_NE(html.find("<th>bounce height (m)</th><td>&ndash;</td>"), std::string::npos);
  EXPECT_EQ(html.find("<th>evaluation_lines</th>"), std::string::npos);  // not as raw JSON
  input.summary_json = R"({"rocks": 4})";
  EXPECT_EQ(RunReportHtml(input).find("Evaluation lines"), std::string::npos);
}

TEST(ReportHtml, ShowsTheBarriersSummary) {
  RunReportInput input;
  input.summary_json = R"({"rocks": 10, "barriers": [{"name": "net <B>", "type": "flexible_net",
      "length_m": 50, "height_m": 4, "capacity_J": 500000, "rocks": 10, "reached": 6,
      "stopped": 3, "overtopped": 1, "broke_through": 2, "reach_probability": 0.6,
      "passing_probability": 0.3,
      "impact_energy_J": {"mean": 600000, "p50": 400000, "p90": 1200000, "p95": 1200000,
                          "p99": 1200000, "max": 1200000},
      "passing_height_m": {"mean": 1, "p50": 0.5, "p90": 5, "p95": 5, "p99": 5, "max": 5},
      "passing_energy_J": {"mean": null, "p50": null, "p90": null, "p95": null, "p99": null,
                           "max": null}}]})";
  const std::string html = RunReportHtml(input);
  EXPECT_NE(html.find("<h2>Barriers</h2>"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>net &lt;B&gt;</th><td>flexible_net</td><td>4</td><td>500</td>"
                      "<td>10</td><td>6</td><td>3</td><td>1</td><td>2</td><td>30.0 %</td>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<th>kinetic energy at the barrier (kJ)</th><td>600</td><td>400</td>"),
            std::string::npos)
      << html;
  EXPECT_EQ(html.find("<th>barriers</th>"), std::string::npos);  // not as raw JSON
  input.summary_json = R"({"rocks": 4})";
  EXPECT_EQ(RunReportHtml(input).find("Barriers"), std::string::npos);
}

// A forest of explicit trees: its model, stands, breaking law and what the rocks did to it, in
// kJ; no raw JSON; no section without a forest.
TEST(ReportHtml, ShowsTheForestSummary) {
  RunReportInput input;
  input.summary_json = R"({"rocks": 10, "forest": {"model": "trees", "trees": 120,
      "stands": [{"area_m2": 20000, "stems_per_ha": 300, "dbh_cm": 30, "dbh_sd_cm": 5,
                  "trees": 120, "species": "beech"}],
      "stem_height_m": 10, "friction": 0.5,
      "breaking_energy": {"coefficient_J": 38.7, "exponent": 2.31,
                          "law": "E_max = coefficient * DBH[cm]^exponent"},
      "species": [{"name": "beech", "coefficient_J": 38.7, "exponent": 2.31, "factor": 1.6,
                   "e_max_30cm_J": 159936}],
      "impacts": {"rock_stem_pairs": 9, "impacts": 11, "rocks_hitting": 6, "rocks_breaking": 2,
                  "breakages": 3, "stems_hit": 8, "absorbed_J": 250000}}})";
  const std::string html = RunReportHtml(input);
  EXPECT_NE(html.find("<h2>Forest</h2>"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>trees</th><td>120</td></tr>"), std::string::npos) << html;
  EXPECT_NE(html.find("300 stems/ha of DBH 30 cm on 2.00 ha (beech)"), std::string::npos) << html;
  EXPECT_NE(html.find("<tr><th>breaking energy by species (the scene's laws)</th><td>beech: 1.6 "
                      "&times; 38.7 J &times; DBH[cm]<sup>2.31</sup>, 160 kJ at 30 cm</td></tr>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("<tr><th>stems broken</th><td>3</td></tr>"), std::string::npos);
  EXPECT_NE(html.find("<tr><th>energy the stems absorbed (kJ)</th><td>250</td></tr>"),
            std::string::npos)
      << html;
  EXPECT_EQ(html.find("<th>forest</th>"), std::string::npos);  // not as raw JSON
  input.summary_json = R"({"rocks": 4})";
  EXPECT_EQ(RunReportHtml(input).find("Forest"), std::string::npos);
}

}  // namespace
}  // namespace talus::io
