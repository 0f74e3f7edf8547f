// tree_impacts.csv (io/tree_impacts_csv.cpp): a row per rock and stem it touched, in rock order,
// complete or absent; the forest's summary counts rocks, stems, impacts and breakages from it.

#include "io/tree_impacts_csv.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "test_files.hpp"

namespace talus::io {
namespace {

ensemble::RockOutcome Rock(long k, std::vector<std::pair<int, bool>> stems) {
  ensemble::RockOutcome rock;
  rock.rock = k;
  for (const auto& [stem, broken] : stems) {
    StemHit& h = rock.result.stem_hits.emplace_back();
    h.stem = stem;
    h.impacts = broken ? 1 : 2;
    h.t_s = 1.5;
    h.energy_J = 5000;
    h.absorbed_J = broken ? 3000 : 1000;
    h.broken = broken;
  }
  return rock;
}

TEST(TreeImpactsCsv, RowsPerRockAndStemAndTheirSummary) {
  const auto dir = testing::FreshDir("trees");
  const auto path = (dir / "tree_impacts.csv").string();
  const Forest forest({Stem{{10, 20}, 0.3, 0}, Stem{{12, 20}, 0.2, 0}}, ForestModel{});
  ensemble::ReleaseSpec release;
  release.releases.push_back({ensemble::ReleaseGeometry::Kind::kPoint, {{{0, 0}}}});
  {
    TreeImpactsCsvWriter csv(path, forest, release);
    csv.Write(Rock(0, {{0, false}, {1, true}}));
    csv.Write(ensemble::RockOutcome{});  // no stem touched: no row
    csv.Write(Rock(2, {{0, true}}));
    EXPECT_FALSE(std::filesystem::exists(path));  // complete or absent
    csv.Commit();
  }
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), std::string(TreeImpactsCsvWriter::Header()) + "\n" +
                            "0,0,0,0,10,20,30,2,1.5,0,0,0,5000,1000,0,\n"
                            "1,0,0,0,12,20,20,1,1.5,0,0,0,5000,3000,1,\n"
                            "0,2,0,0,10,20,30,1,1.5,0,0,0,5000,3000,1,\n");
  const TreeImpactSummary s = SummarizeTreeImpacts(path);
  EXPECT_EQ(s.rows, 3);
  EXPECT_EQ(s.impacts, 4);
  EXPECT_EQ(s.rocks_hitting, 2);
  EXPECT_EQ(s.rocks_breaking, 2);
  EXPECT_EQ(s.breakages, 2);
  EXPECT_EQ(s.stems_hit, 2);
  EXPECT_EQ(s.absorbed_J, 7000);
}

// A stem of a species: its name in the last column (quoted as text fields are), empty for none.
TEST(TreeImpactsCsv, TheSpeciesIsTheLastColumn) {
  const auto dir = testing::FreshDir("trees");
  const auto path = (dir / "tree_impacts.csv").string();
  ForestModel model;
  TreeSpecies beech;
  beech.name = "Fagus sylvatica, old";
  beech.energy_factor = 1.6;
  model.species = {beech};
  const Forest forest({Stem{{10, 20}, 0.3, 0, 0}, Stem{{12, 20}, 0.2, 0, -1}}, model);
  ensemble::ReleaseSpec release;
  release.releases.push_back({ensemble::ReleaseGeometry::Kind::kPoint, {{{0, 0}}}});
  {
    TreeImpactsCsvWriter csv(path, forest, release);
    csv.Write(Rock(0, {{0, false}, {1, true}}));
    csv.Commit();
  }
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), std::string(TreeImpactsCsvWriter::Header()) + "\n" +
                            "0,0,0,0,10,20,30,2,1.5,0,0,0,5000,1000,0,\"Fagus sylvatica, old\"\n"
                            "1,0,0,0,12,20,20,1,1.5,0,0,0,5000,3000,1,\n");
  EXPECT_EQ(std::string(TreeImpactsCsvWriter::Header())
                .substr(std::string(TreeImpactsCsvWriter::Header()).rfind(',')),
            ",species");
}

}  // namespace
}  // namespace talus::io
