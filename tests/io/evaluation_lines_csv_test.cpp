#include "io/evaluation_lines_csv.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "common/error.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<ensemble::EvaluationLine> TwoLines() {
  return {{"barrier A", {{0, 0}, {3, 4}}}, {"net, lower", {{0, 1}, {0, 2}, {0, 4}}}};
}

TEST(EvaluationLinesCsvWriter, OneRowPerRockAndLineCrossedInRockOrder) {
  const auto dir = testing::FreshDir("csv");
  const auto path = (dir / "evaluation_lines.csv").string();
  const std::vector<ensemble::EvaluationLine> lines = TwoLines();
  ensemble::ReleaseSpec release;
  release.runs.resize(2);
  release.runs[0].id = "v001";
  release.runs[1].id = "v002";
  {
    EvaluationLinesCsvWriter csv(path, lines, release);
    for (long k = 0; k < 3; ++k) {
      ensemble::RockOutcome rock;
      rock.rock = k;
      rock.release = 1;
      if (k == 1) {  // rock 1 never crosses: no row
        csv.Write(rock);
        continue;
      }
      for (int line : {0, 1}) {
        ensemble::LineCrossing& c = rock.line_crossings.emplace_back();
        c.line = line;
        c.t_s = 1.5;
        c.position_m = {1, 2, 3};
        c.speed_m_s = 4;
        c.translational_energy_J = 1000;
        c.rotational_energy_J = 250.5;
        c.com_height_m = 0.75;
        c.bounce_height_m = 0.25;
        c.crossings = 2 + k;
      }
      csv.Write(rock);
    }
    EXPECT_FALSE(std::filesystem::exists(path));  // complete or absent
    csv.Commit();
  }
  EXPECT_EQ(Slurp(path),
            "line,rock,release,run,t_s,x_m,y_m,z_m,speed_m_s,translational_energy_J,"
            "rotational_energy_J,energy_J,com_height_m,bounce_height_m,crossings\n"
            "barrier A,0,1,v002,1.5,1,2,3,4,1000,250.5,1250.5,0.75,0.25,2\n"
            "\"net, lower\",0,1,v002,1.5,1,2,3,4,1000,250.5,1250.5,0.75,0.25,2\n"
            "barrier A,2,1,v002,1.5,1,2,3,4,1000,250.5,1250.5,0.75,0.25,4\n"
            "\"net, lower\",2,1,v002,1.5,1,2,3,4,1000,250.5,1250.5,0.75,0.25,4\n");
}

// Nearest rank (the smallest value with at least p % of the values at or below it) of the 20 values
// 1 .. 20: p50 = 10th, p90 = 18th, p95 = 19th, p99 = 20th value; mean 10.5.
TEST(SummarizeEvaluationLines, NearestRankStatisticsAndPassingProbability) {
  const auto dir = testing::FreshDir("summary");
  const auto path = (dir / "evaluation_lines.csv").string();
  std::string csv = std::string(EvaluationLinesCsvWriter::Header()) + "\n";
  // 25 rocks: 20 cross "barrier A" (speeds 1 .. 20 in a scrambled order; energy 100 x speed,
  // heights speed / 10 and speed / 100), none crosses "net, lower".
  for (int k = 0, i = 0; k < 25; ++k) {
    if (k % 5 == 4) continue;          // rocks 4, 9, 14, 19, 24 never cross
    const int v = 1 + (i++ * 7) % 20;  // 7 and 20 are coprime: a permutation of 1 .. 20
    csv += "barrier A," + std::to_string(k) + ",0,0,1,2,3,4," + std::to_string(v) + ",0,0," +
           std::to_string(100 * v) + "," + std::to_string(v / 10.0) + "," +
           std::to_string(v / 100.0) + ",1\n";
  }
  testing::WriteText(path, csv);
  const auto summary = SummarizeEvaluationLines(path, TwoLines(), 25);
  ASSERT_EQ(summary.size(), 2u);
  const EvaluationLineSummary& a = summary[0];
  EXPECT_EQ(a.name, "barrier A");
  EXPECT_DOUBLE_EQ(a.length_m, 5);
  EXPECT_EQ(a.rocks, 25);
  EXPECT_EQ(a.crossed, 20);
  EXPECT_DOUBLE_EQ(a.passing_probability, 0.8);
  const std::array<double, 6> speed = {10.5, 10, 18, 19, 20, 20};
  for (std::size_t k = 0; k < 6; ++k) {
    EXPECT_DOUBLE_EQ(a.speed_m_s.values[k], speed[k]) << CrossingStatistics::kNames[k];
    EXPECT_DOUBLE_EQ(a.energy_J.values[k], 100 * speed[k]) << CrossingStatistics::kNames[k];
    EXPECT_NEAR(a.com_height_m.values[k], speed[k] / 10, 1e-12);
    EXPECT_NEAR(a.bounce_height_m.values[k], speed[k] / 100, 1e-12);
  }
  const EvaluationLineSummary& b = summary[1];
  EXPECT_EQ(b.crossed, 0);
  EXPECT_DOUBLE_EQ(b.passing_probability, 0);
  for (double v : b.speed_m_s.values) EXPECT_TRUE(std::isnan(v));

  const std::string table = EvaluationLinesSummaryCsv(summary);
  EXPECT_EQ(table.substr(0, table.find('\n')),
            "name,length_m,rocks,crossed,passing_probability,speed_mean_m_s,speed_p50_m_s,"
            "speed_p90_m_s,speed_p95_m_s,speed_p99_m_s,speed_max_m_s,energy_mean_J,energy_p50_J,"
            "energy_p90_J,energy_p95_J,energy_p99_J,energy_max_J,com_height_mean_m,"
            "com_height_p50_m,com_height_p90_m,com_height_p95_m,com_height_p99_m,com_height_max_m,"
            "bounce_height_mean_m,bounce_height_p50_m,bounce_height_p90_m,bounce_height_p95_m,"
            "bounce_height_p99_m,bounce_height_max_m");
  EXPECT_NE(
      table.find("\nbarrier A,5,25,20,0.8,10.5,10,18,19,20,20,1050,1000,1800,1900,2000,2000,"),
      std::string::npos)
      << table;
  EXPECT_NE(table.find("\n\"net, lower\",3,25,0,0,,,,,,,,,,,,,,,,,,,,,,,,\n"), std::string::npos)
      << table;
  // Read again as often as a budget of one value needs (common/column_statistics.hpp): the same.
  EXPECT_EQ(EvaluationLinesSummaryCsv(SummarizeEvaluationLines(path, TwoLines(), 25, 8)), table);
}

TEST(SummarizeEvaluationLines, RowsOfUnknownLinesOrWithoutNumbersAreErrors) {
  const auto dir = testing::FreshDir("bad");
  const auto path = (dir / "evaluation_lines.csv").string();
  const std::string header = std::string(EvaluationLinesCsvWriter::Header()) + "\n";
  testing::WriteText(path, header + "fence,0,0,0,1,2,3,4,5,6,7,8,9,10,1\n");
  try {
    SummarizeEvaluationLines(path, TwoLines(), 1);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":2: column 'line': 'fence' is not an evaluation line"),
              std::string::npos)
        << e.what();
  }
  testing::WriteText(path, header + "barrier A,0,0,0,1,2,3,4,fast,6,7,8,9,10,1\n");
  try {
    SummarizeEvaluationLines(path, TwoLines(), 1);
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(":2: column 'speed_m_s': 'fast' is not a number"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace talus::io
