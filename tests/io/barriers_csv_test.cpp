#include "io/barriers_csv.hpp"

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

std::vector<Barrier> TwoBarriers() {
  Barrier net{"net, lower", BarrierType::kFlexibleNet, {{0, 0}, {3, 4}}, 3, 500000};
  Barrier dam{"dam", BarrierType::kDam, {{0, 1}, {0, 9}}, 6, 5e6};
  return {net, dam};
}

// Rock k reached the net with `energy_J` (3/4 translational) at a passing height of k / 2 m and
// left it as `outcome` with `after_J`.
ensemble::RockOutcome Rock(long k, BarrierOutcome outcome, double energy_J, double after_J) {
  ensemble::RockOutcome rock;
  rock.rock = k;
  BarrierEvent& e = rock.result.barrier_events.emplace_back();
  e.barrier = 0;
  e.outcome = outcome;
  e.t_s = 2.5;
  e.position_m = {1, 2, 3};
  e.speed_m_s = 10;
  e.translational_energy_J = 0.75 * energy_J;
  e.rotational_energy_J = 0.25 * energy_J;
  e.passing_height_m = 0.5 * double(k);
  e.com_height_m = 0.5 * double(k) + 0.4;
  e.energy_after_J = after_J;
  return rock;
}

TEST(BarriersCsv, RowsInRockOrderAndASummaryOfCountsAndNearestRankStatistics) {
  const auto dir = testing::FreshDir("barriers");
  const auto path = (dir / "barriers.csv").string();
  const std::vector<Barrier> barriers = TwoBarriers();
  ensemble::ReleaseSpec release;
  release.releases.push_back({ensemble::ReleaseGeometry::Kind::kPoint, {{{0, 0}}}});
  {
    BarriersCsvWriter csv(path, barriers, release);
    csv.Write(Rock(0, BarrierOutcome::kStopped, 400000, 0));
    csv.Write(ensemble::RockOutcome{});  // a rock that reached no barrier: no row
    csv.Write(Rock(2, BarrierOutcome::kBrokeThrough, 800000, 300000));
    csv.Write(Rock(3, BarrierOutcome::kOvertopped, 200000, 200000));
    csv.Write(Rock(4, BarrierOutcome::kBrokeThrough, 600000, 100000));
    EXPECT_FALSE(std::filesystem::exists(path));  // complete or absent
    csv.Commit();
  }
  const std::string text = Slurp(path);
  EXPECT_EQ(text.substr(0, text.find('\n')), BarriersCsvWriter::Header());
  EXPECT_NE(text.find("\n\"net, lower\",flexible_net,0,0,0,stopped,2.5,1,2,3,10,300000,"
                      "100000,400000,0,0.4,0\n"),
            std::string::npos)
      << text;

  const std::vector<BarrierSummary> s = SummarizeBarriers(path, barriers, 5);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].name, "net, lower");
  EXPECT_EQ(s[0].type, "flexible_net");
  EXPECT_EQ(s[0].length_m, 5);
  EXPECT_EQ(s[0].reached, 4);
  EXPECT_EQ(s[0].stopped, 1);
  EXPECT_EQ(s[0].overtopped, 1);
  EXPECT_EQ(s[0].broke_through, 2);
  EXPECT_DOUBLE_EQ(s[0].reach_probability, 0.8);
  EXPECT_DOUBLE_EQ(s[0].passing_probability, 0.6);
  // Impact energies 400, 800, 200, 600 kJ: mean 500, nearest-rank median (rank ceil(0.5 * 4) = 2
  // of 200, 400, 600, 800) 400, p90 .. max 800.
  EXPECT_DOUBLE_EQ(s[0].impact_energy_J.values[0], 500000);
  EXPECT_DOUBLE_EQ(s[0].impact_energy_J.values[1], 400000);
  EXPECT_DOUBLE_EQ(s[0].impact_energy_J.values[5], 800000);
  // The energies after the barrier of the three that passed: 300, 200, 100 kJ.
  EXPECT_DOUBLE_EQ(s[0].passing_energy_J.values[0], 200000);
  EXPECT_DOUBLE_EQ(s[0].passing_energy_J.values[5], 300000);
  EXPECT_DOUBLE_EQ(s[0].passing_height_m.values[5], 2);
  // The dam: no rock reached it; its statistics are missing (NaN), its counts 0.
  EXPECT_EQ(s[1].reached, 0);
  EXPECT_TRUE(std::isnan(s[1].impact_energy_J.values[1]));
  const std::string table = BarriersSummaryCsv(s);
  EXPECT_EQ(table.substr(0, table.find(',', table.find("passing_probability"))),
            "name,type,length_m,height_m,capacity_J,rocks,reached,stopped,overtopped,"
            "broke_through,reach_probability,passing_probability");
  EXPECT_NE(table.find("\ndam,dam,8,6,5000000,5,0,0,0,0,0,0,,"), std::string::npos) << table;
  // Read again as often as a budget of one value needs: the same counts and statistics.
  EXPECT_EQ(BarriersSummaryCsv(SummarizeBarriers(path, barriers, 5, 8)), table);
}

TEST(BarriersCsv, ARowOfAnotherSceneIsAnErrorNamingTheLine) {
  const auto dir = testing::FreshDir("barriers");
  const auto path = (dir / "barriers.csv").string();
  testing::WriteText(dir / "barriers.csv",
                     std::string(BarriersCsvWriter::Header()) +
                         "\nfence,flexible_net,0,0,a,stopped,1,1,1,1,1,1,1,1,1,1,0\n");
  try {
    SummarizeBarriers(path, TwoBarriers(), 1);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("barriers.csv:2: column 'barrier': 'fence'"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace talus::io
