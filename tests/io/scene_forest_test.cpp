// [forest] of a scene file (io/scene_forest.cpp) through io::LoadScene: a tree list becomes
// Scene::forest's stems (DBH cm -> m, foot on the terrain), stands draw the same trees at every
// load from the forest's seed (a Poisson process: the count within its spread), a run gives the
// same impacts for any number of threads, and bad input is an error naming the file, line and key
// before any rock runs.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iterator>
#include <mutex>
#include <string>

#include "common/error.hpp"
#include "ensemble/runner.hpp"
#include "io/rocks_csv.hpp"
#include "io/scene_file.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

// A 60 x 30 m plane (x 0 .. 60, y -15 .. 15, 1 m cells, 30 deg falling along +x).
const std::string kScene = R"([terrain]
plane = { slope_deg = 30, slope_length_m = 40, runout_m = 20, width_m = 30, cell_m = 1 }

[rock]
shape = { box = [0.5, 0.4, 0.3] }

[release]
points = [[5, 0]]
rocks = 8
seed = 4

)";

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

SceneFile Load(const std::string& table, const std::string& trees_csv = "",
               const std::string& scene = kScene) {
  const auto dir = testing::FreshDir("scene");
  if (!trees_csv.empty()) testing::WriteText(dir / "trees.csv", trees_csv);
  testing::WriteText(dir / "scene.toml", scene + table);
  return LoadScene((dir / "scene.toml").string());
}

std::string ErrorOf(const std::string& table, const std::string& trees_csv = "") {
  try {
    Load(table, trees_csv);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const std::string kStand =
    "[forest]\nstands = [{ polygon = [[20, -10], [40, -10], [40, 10], [20, 10]], "
    "stems_per_ha = 5000, dbh_cm = 30, dbh_sd_cm = 5 }]\n";

TEST(SceneForest, ATreeListBecomesTheStems) {
  const SceneFile s = Load("[forest]\ntrees = \"trees.csv\"\nstem_height_m = 8\n",
                           "x_m,y_m,dbh_cm\n30,0,30\n35.5,-2,12\n");
  ASSERT_EQ(s.scene.forest.stems().size(), 2u);
  const Stem& a = s.scene.forest.stems()[0];
  EXPECT_EQ(a.position_m, Eigen::Vector2d(30, 0));
  EXPECT_DOUBLE_EQ(a.dbh_m, 0.30);
  double ground = 0;
  ASSERT_TRUE(s.scene.terrain.Height(30, 0, &ground));
  EXPECT_EQ(a.ground_m, ground);
  EXPECT_EQ(s.scene.forest.model().stem_height_m, 8);
  EXPECT_TRUE(s.has_forest);
  EXPECT_EQ(s.trees_from_file, 2);
  EXPECT_EQ(s.inputs.back(), s.trees_file);
  // Without a [forest]: no trees, no forest work.
  EXPECT_TRUE(Load("").scene.forest.empty());
}

TEST(SceneForest, StandsDrawTheSameTreesAtEveryLoadFromTheForestSeed) {
  const SceneFile a = Load(kStand), b = Load(kStand);
  const std::vector<Stem>& stems = a.scene.forest.stems();
  ASSERT_EQ(stems.size(), b.scene.forest.stems().size());
  for (std::size_t k = 0; k < stems.size(); ++k) {
    EXPECT_EQ(stems[k].position_m, b.scene.forest.stems()[k].position_m);
    EXPECT_EQ(stems[k].dbh_m, b.scene.forest.stems()[k].dbh_m);
  }
  // Poisson: mean 5000/ha * 0.04 ha = 200, standard deviation sqrt(200) = 14.1; 4 sigma.
  EXPECT_NEAR(static_cast<double>(stems.size()), 200, 4 * std::sqrt(200.0));
  ASSERT_EQ(a.stands.size(), 1u);
  EXPECT_EQ(a.stands[0].trees, static_cast<long>(stems.size()));
  EXPECT_DOUBLE_EQ(a.stands[0].area_m2, 400);
  double sum = 0, squares = 0;
  for (const Stem& s : stems) {
    EXPECT_TRUE(s.position_m.x() >= 20 && s.position_m.x() <= 40 &&
                std::abs(s.position_m.y()) <= 10);
    sum += 100 * s.dbh_m;
    squares += 1e4 * s.dbh_m * s.dbh_m;
  }
  const double n = static_cast<double>(stems.size());
  const double mean = sum / n, sd = std::sqrt(squares / n - mean * mean);
  // The sample mean of ~200 normal DBHs (sd 5 cm) within 4 standard errors (1.4 cm); the sample
  // spread within 25 %.
  EXPECT_NEAR(mean, 30, 1.5);
  EXPECT_NEAR(sd, 5, 1.25);
  // The default seed is the release's; another seed draws another forest.
  EXPECT_EQ(a.forest_seed, 4u);
  const SceneFile c = Load(kStand + "seed = 5\n");
  EXPECT_NE(c.scene.forest.stems().front().position_m, stems.front().position_m);
}

// Collects each rock's outcome, in rock order.
class Collect : public ensemble::RockSink {
 public:
  void OnRock(const ensemble::RockOutcome& outcome) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    rocks.push_back(outcome);
  }
  std::vector<ensemble::RockOutcome> rocks;

 private:
  std::mutex mutex_;
};

TEST(SceneForest, ARunHitsTheSameStemsForAnyNumberOfThreads) {
  // Thrown down the slope at 6 m/s in random orientations, so that they reach the stand.
  std::string scene = kScene;
  scene.replace(scene.find("seed = 4\n"), 9,
                "seed = 4\nvelocity_m_s = [6, 0, 0]\norientation = \"random\"\n");
  const SceneFile s = Load(kStand, "", scene);
  std::vector<std::vector<ensemble::RockOutcome>> runs;
  for (int threads : {1, 2}) {
    ensemble::EnsembleOptions options;
    options.threads = threads;
    Collect sink;
    ensemble::RunEnsemble(s.scene, s.release, options, &sink);
    std::sort(sink.rocks.begin(), sink.rocks.end(),
              [](const auto& a, const auto& b) { return a.rock < b.rock; });
    runs.push_back(sink.rocks);
  }
  ASSERT_EQ(runs[0].size(), runs[1].size());
  long hits = 0;
  for (std::size_t k = 0; k < runs[0].size(); ++k) {
    const RockResult &a = runs[0][k].result, &b = runs[1][k].result;
    EXPECT_EQ(a.final_state.position_m, b.final_state.position_m) << "rock " << k;
    ASSERT_EQ(a.stem_hits.size(), b.stem_hits.size()) << "rock " << k;
    for (std::size_t h = 0; h < a.stem_hits.size(); ++h) {
      EXPECT_EQ(a.stem_hits[h].stem, b.stem_hits[h].stem);
      EXPECT_EQ(a.stem_hits[h].absorbed_J, b.stem_hits[h].absorbed_J);
      EXPECT_EQ(a.stem_hits[h].broken, b.stem_hits[h].broken);
    }
    hits += static_cast<long>(a.stem_hits.size());
  }
  EXPECT_GT(hits, 0) << "the rocks run into the stand";
}

// A point vector file of trees (GeoJSON here; any file GDAL/OGR reads): each point with the DBH of
// its dbh_field attribute. A GeoJSON without a "crs" member on the plane (no CRS) is taken as
// local coordinates.
TEST(SceneForest, APointVectorFileOfTreesWithItsDbhField) {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "trees.geojson", R"({"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"d": 25.5}, "geometry": {"type": "Point", "coordinates": [30, 1]}},
{"type": "Feature", "properties": {"d": 40}, "geometry": {"type": "Point", "coordinates": [33, -2]}}]})");
  testing::WriteText(dir / "scene.toml",
                     kScene + "[forest]\ntrees = \"trees.geojson\"\ndbh_field = \"d\"\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.scene.forest.stems().size(), 2u);
  EXPECT_EQ(s.scene.forest.stems()[1].position_m, Eigen::Vector2d(33, -2));
  EXPECT_DOUBLE_EQ(s.scene.forest.stems()[0].dbh_m, 0.255);
  // Without the field, and with a DBH out of bounds: errors naming the file and the feature.
  testing::WriteText(dir / "scene.toml", kScene + "[forest]\ntrees = \"trees.geojson\"\n");
  try {
    LoadScene((dir / "scene.toml").string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_HAS(e.what(), "forest.trees (");
    EXPECT_HAS(e.what(), "trees.geojson, feature 0): no field 'dbh_cm'");
  }
}

// A file in another CRS is reprojected to the DEM's (cases/tirol's EPSG:31287 from WGS 84), to
// the same place as a release point of that file; a file with a CRS is refused in a scene without
// one.
TEST(SceneForest, ATreeFileInAnotherCrsIsReprojectedOrRefused) {
  const auto dir = testing::FreshDir("scene");
  // (256500, 379700) in EPSG:31287, by gdaltransform.
  testing::WriteText(dir / "trees.geojson", R"({"type": "FeatureCollection",
"crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:OGC:1.3:CRS84"}}, "features": [
{"type": "Feature", "properties": {"dbh_cm": 30}, "geometry": {"type": "Point", "coordinates": [11.4343407630182, 47.3010011178257]}}]})");
  const std::string tirol = std::string(TALUS_SOURCE_DIR) + "/cases/tirol/";
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\ndem = \"" + tirol +
                         "dem.tif\"\n[rock]\n"
                         "shape = { box = [1, 1, 1] }\n[release]\nfile = \"trees.geojson\"\n"
                         "[forest]\ntrees = \"trees.geojson\"\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.scene.forest.stems().size(), 1u);
  const Eigen::Vector2d tree = s.scene.forest.stems()[0].position_m;
  EXPECT_NEAR(tree.x(), 256500, 0.01);  // 1 cm: gdaltransform's printed digits
  EXPECT_NEAR(tree.y(), 379700, 0.01);
  EXPECT_EQ(tree, s.release.releases.at(0).rings.at(0).at(0));
  testing::WriteText(dir / "local.geojson", R"({"type": "FeatureCollection",
"crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::31287"}}, "features": [
{"type": "Feature", "properties": {"dbh_cm": 30}, "geometry": {"type": "Point", "coordinates": [30, 0]}}]})");
  testing::WriteText(dir / "scene.toml", kScene + "[forest]\ntrees = \"local.geojson\"\n");
  try {
    LoadScene((dir / "scene.toml").string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_HAS(e.what(), "has a CRS but the DEM has none, so the trees cannot be placed");
  }
}

// stands_file: the polygons of a vector file with stems_per_ha, dbh_cm (and dbh_sd_cm), drawn as
// inline stands are, after them; a hole is left empty.
TEST(SceneForest, StandsFromAVectorFileOfPolygons) {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "stands.geojson", R"({"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"stems_per_ha": 3000, "dbh_cm": 20},
 "geometry": {"type": "Polygon", "coordinates": [[[20, -10], [40, -10], [40, 10], [20, 10], [20, -10]],
                                                 [[25, -5], [35, -5], [35, 5], [25, 5], [25, -5]]]}}]})");
  testing::WriteText(dir / "scene.toml", kScene + "[forest]\nstands_file = \"stands.geojson\"\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.stands.size(), 1u);
  EXPECT_DOUBLE_EQ(s.stands[0].area_m2, 300);  // 400 less the 100 m^2 hole
  // Poisson with mean 3000/ha * 0.03 ha = 90: within 4 sigma (38).
  EXPECT_NEAR(static_cast<double>(s.scene.forest.stems().size()), 90, 4 * std::sqrt(90.0));
  for (const Stem& stem : s.scene.forest.stems()) {
    EXPECT_FALSE(std::abs(stem.position_m.x() - 30) < 5 && std::abs(stem.position_m.y()) < 5)
        << "a tree in the hole";
    EXPECT_DOUBLE_EQ(stem.dbh_m, 0.2);
  }
  testing::WriteText(dir / "stands.geojson", R"({"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"stems_per_ha": 0, "dbh_cm": 20},
 "geometry": {"type": "Polygon", "coordinates": [[[20, -10], [40, -10], [40, 10], [20, -10]]]}}]})");
  try {
    LoadScene((dir / "scene.toml").string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_HAS(e.what(), "stands.geojson, feature 0): stems_per_ha: 0 must be > 0");
  }
}

TEST(SceneForest, BadInputIsAnErrorNamingFileLineAndKey) {
  EXPECT_HAS(ErrorOf("[forest]\nstem_height_m = 10\n"), "forest.trees: a [forest] needs trees");
  EXPECT_HAS(ErrorOf("[forest]\ntrees = \"trees.csv\"\n", "x_m,y_m,dbh_cm\n30,0,-5\n"),
             "trees.csv:2: column 'dbh_cm': -5 cm must be > 0");
  EXPECT_HAS(ErrorOf("[forest]\ntrees = \"trees.csv\"\n", "x_m,y_m,dbh\n30,0,5\n"), "dbh_cm");
  EXPECT_HAS(ErrorOf("[forest]\ntrees = \"trees.csv\"\n", "x_m,y_m,dbh_cm\n30,0,30\n600000,0,30\n"),
             "trees.csv:3: column 'x_m': the tree at (600000, 0) is off the DEM");
  EXPECT_HAS(ErrorOf("[forest]\ntrees = \"missing.csv\"\n"), "scene.toml:13: forest.trees:");
  const std::string stand = "[forest]\nstands = [{ polygon = [[20, -10], [40, -10], [40, 10]], ";
  EXPECT_HAS(ErrorOf(stand + "stems_per_ha = 0, dbh_cm = 30 }]\n"),
             "scene.toml:13: forest.stands[0].stems_per_ha: 0 must be > 0 and <= 10000");
  EXPECT_HAS(ErrorOf(stand + "stems_per_ha = 1e6, dbh_cm = 30 }]\n"), "stems_per_ha: 1000000");
  EXPECT_HAS(ErrorOf(stand + "stems_per_ha = 400, dbh_cm = -30 }]\n"),
             "dbh_cm: -30 cm must be > 0");
  EXPECT_HAS(ErrorOf(stand + "stems_per_ha = 400, dbh_cm = 30, dbh_sd_cm = 40 }]\n"),
             "dbh_sd_cm: 40 cm must be >= 0 and <= dbh_cm");
  EXPECT_HAS(ErrorOf(stand + "stems_per_ha = 400 }]\n"), "forest.stands[0].dbh_cm: missing");
  EXPECT_HAS(ErrorOf("[forest]\nstands = [{ polygon = [[50, -10], [90, -10], [90, 10]], "
                     "stems_per_ha = 400, dbh_cm = 30 }]\n"),
             "is off the DEM or on nodata");
  EXPECT_HAS(ErrorOf(kStand + "friction = -0.5\n"), "forest.friction: -0.5 is outside 0 .. 10");
  EXPECT_HAS(ErrorOf(kStand + "stem_height_m = 0\n"), "forest.stem_height_m: stem_height_m = 0");
  EXPECT_HAS(ErrorOf(kStand + "dbh = 3\n"), "forest.dbh: unknown key");
  EXPECT_HAS(ErrorOf("[output]\nrasters = [\"tree_hits\"]\n"),
             "output.rasters: tree_hits counts the impacts on stems: the scene has no [forest]");
}

// Two species as a scene declares them after its [forest] keys: beech by a factor of the forest's
// law, larch by a coefficient of its own (the forest's exponent). The numbers are the test's, not
// published ones.
const std::string kSpecies =
    "[forest.species.beech]\nenergy_factor = 1.6\n"
    "[forest.species.larch]\nenergy_coefficient_j = 60\n";

TEST(SceneForest, TreesAndStandsOfADeclaredSpeciesBreakByItsLaw) {
  const SceneFile s = Load(
      "[forest]\ntrees = \"trees.csv\"\n"
      "stands = [{ polygon = [[20, -10], [40, -10], [40, 10], [20, 10]], "
      "stems_per_ha = 1000, dbh_cm = 25, species = \"larch\" }]\n" +
          kSpecies,
      "x_m,y_m,dbh_cm,species\n30,0,30,beech\n32,1,30,\n34,2,30,larch\n");
  const Forest& forest = s.scene.forest;
  ASSERT_EQ(forest.model().species.size(), 2u);
  EXPECT_EQ(forest.model().species[0].name, "beech");
  EXPECT_EQ(forest.model().species[1].name, "larch");
  const double e30 = ForestModel{}.BreakingEnergy_J(0.30);
  ASSERT_GT(forest.stems().size(), 3u);
  EXPECT_EQ(forest.stems()[0].species, 0);
  EXPECT_EQ(forest.capacity_J(0), 1.6 * e30);
  EXPECT_EQ(forest.stems()[1].species, -1);  // an empty cell: the forest's law
  EXPECT_EQ(forest.capacity_J(1), e30);
  EXPECT_EQ(forest.stems()[2].species, 1);
  EXPECT_NEAR(forest.capacity_J(2), 60 * std::pow(30.0, 2.31), 1e-9 * forest.capacity_J(2));
  for (std::size_t k = 3; k < forest.stems().size(); ++k) {
    EXPECT_EQ(forest.stems()[k].species, 1);  // the stand's
    EXPECT_EQ(forest.capacity_J(static_cast<int>(k)),
              forest.model().BreakingEnergy_J(forest.stems()[k].dbh_m, 1));
  }
  ASSERT_EQ(s.stands.size(), 1u);
  EXPECT_EQ(s.stands[0].species, "larch");
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
}

TEST(SceneForest, BadSpeciesIsAnErrorNamingFileLineAndKey) {
  // Lines: 12 [forest], 13 trees, 14 [forest.species.beech], 15 its first key.
  const std::string trees = "[forest]\ntrees = \"trees.csv\"\n";
  const std::string beech = trees + "[forest.species.beech]\n";
  const std::string csv = "x_m,y_m,dbh_cm,species\n30,0,30,beech\n";
  EXPECT_HAS(ErrorOf(trees + kSpecies, csv + "32,0,30,oak\n"),
             "trees.csv:3: column 'species': species 'oak' is not declared in [forest.species] "
             "(declared: 'beech', 'larch')");
  EXPECT_HAS(ErrorOf(beech + "energy_factor = 2\nenergy_coefficient_j = 60\n", csv),
             "scene.toml:15: forest.species.beech.energy_factor: a species gives energy_factor "
             "(E_max = factor x the forest's law) or a law of its own");
  EXPECT_HAS(ErrorOf(beech + "energy_exponent = 2\nenergy_factor = 2\n", csv),
             "scene.toml:16: forest.species.beech.energy_factor: a species gives energy_factor");
  EXPECT_HAS(ErrorOf(beech + "energy_factor = 0\n", csv),
             "scene.toml:15: forest.species.beech.energy_factor: energy_factor = 0 must be finite "
             "and > 0");
  EXPECT_HAS(ErrorOf(beech + "energy_factor = -1\n", csv),
             "scene.toml:15: forest.species.beech.energy_factor: -1 is outside 0 .. 100");
  EXPECT_HAS(ErrorOf(beech + "energy_factor = 500\n", csv), "500 is outside 0 .. 100");
  EXPECT_HAS(ErrorOf(beech + "energy_coefficient_j = -60\n", csv),
             "forest.species.beech.energy_coefficient_j: energy_coefficient_j = -60 must be");
  EXPECT_HAS(ErrorOf(beech + "energy_factr = 2\n", csv),
             "scene.toml:15: forest.species.beech.energy_factr: unknown key (did you mean "
             "'energy_factor'?)");
  EXPECT_HAS(ErrorOf(beech + "height_m = 2\n", csv),
             "scene.toml:15: forest.species.beech.height_m: unknown key");
  EXPECT_HAS(ErrorOf(beech, csv), "forest.species.beech.energy_factor: missing");
  EXPECT_HAS(ErrorOf(trees + "species = 3\n", csv), "forest.species: expected tables");
  EXPECT_HAS(ErrorOf(trees + "[forest.species.\"a\\tb\"]\nenergy_factor = 2\n", csv),
             "without control characters");
  // An inline stand naming an undeclared species.
  EXPECT_HAS(ErrorOf("[forest]\nstands = [{ polygon = [[20, -10], [40, -10], [40, 10]], "
                     "stems_per_ha = 400, dbh_cm = 30, species = \"oak\" }]\n" +
                     kSpecies),
             "scene.toml:13: forest.stands[0].species: species 'oak' is not declared in "
             "[forest.species] (declared: 'beech', 'larch')");
  // Keys for another kind of input.
  EXPECT_HAS(ErrorOf(trees + "species_field = \"art\"\n" + kSpecies, csv),
             "forest.species_field: a CSV tree list has its species in the column species");
  EXPECT_HAS(ErrorOf(kStand + "raster_species = \"beech\"\n" + kSpecies),
             "forest.raster_species: raster_species is for model = \"drag\"");
  EXPECT_HAS(ErrorOf(kStand + "model = \"drag\"\nraster_species = \"beech\"\n" + kSpecies),
             "forest.raster_species: names the species of the stands of stems_per_ha_raster");
  EXPECT_HAS(ErrorOf(kStand + "model = \"drag\"\nspecies_field = \"art\"\n" + kSpecies),
             "forest.species_field: model = \"drag\" has no explicit trees");
}

TEST(SceneForest, UnusedSpeciesAndUndeclaredSpeciesInAFileAreWarnings) {
  const SceneFile s = Load("[forest]\ntrees = \"trees.csv\"\n" + kSpecies,
                           "x_m,y_m,dbh_cm,species\n30,0,30,beech\n");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_HAS(
      s.warnings[0],
      "scene.toml:16: forest.species.larch: forest: declared, but no tree or stand names it");
  // A tree list with a species column in a scene that declares no species (an inventory written
  // before [forest.species]): it loads as before, every stem of the forest's law, with a warning.
  const SceneFile plain =
      Load("[forest]\ntrees = \"trees.csv\"\n", "x_m,y_m,dbh_cm,species\n30,0,30,Picea abies\n");
  EXPECT_EQ(plain.scene.forest.stems().at(0).species, -1);
  EXPECT_EQ(plain.scene.forest.capacity_J(0), ForestModel{}.BreakingEnergy_J(0.30));
  ASSERT_EQ(plain.warnings.size(), 1u);
  EXPECT_HAS(plain.warnings[0],
             "trees.csv:2: column 'species': forest: names a species, but the scene declares none");
}

// A point vector file of trees: the species in the attribute species_field ("species" by default,
// read when the layer has it; a null value is no species); a species_field the layer lacks is an
// error when the scene names it.
TEST(SceneForest, AVectorTreeFileGivesEachTreeTheSpeciesOfItsSpeciesField) {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "trees.geojson", R"({"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"dbh_cm": 30, "species": "beech", "art": "larch"}, "geometry": {"type": "Point", "coordinates": [30, 1]}},
{"type": "Feature", "properties": {"dbh_cm": 30, "species": null, "art": "larch"}, "geometry": {"type": "Point", "coordinates": [33, -2]}}]})");
  const auto load = [&](const std::string& keys) {
    testing::WriteText(dir / "scene.toml",
                       kScene + "[forest]\ntrees = \"trees.geojson\"\n" + keys + kSpecies);
    return LoadScene((dir / "scene.toml").string());
  };
  SceneFile s = load("");
  ASSERT_EQ(s.scene.forest.stems().size(), 2u);
  EXPECT_EQ(s.scene.forest.stems()[0].species, 0);
  EXPECT_EQ(s.scene.forest.stems()[1].species, -1);
  ASSERT_EQ(s.warnings.size(), 1u);  // larch
  s = load("species_field = \"art\"\n");
  EXPECT_EQ(s.scene.forest.stems()[0].species, 1);
  EXPECT_EQ(s.scene.forest.stems()[1].species, 1);
  try {
    load("species_field = \"sorte\"\n");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_HAS(e.what(), "trees.geojson, feature 0): no field 'sorte' (species_field");
    EXPECT_HAS(e.what(), "the fields are: dbh_cm, species, art");
  }
}

// stands_file: a polygon's attribute species (when the layer has it) is the stand's species.
TEST(SceneForest, StandsOfAFileTakeTheSpeciesOfTheirAttribute) {
  const auto dir = testing::FreshDir("scene");
  testing::WriteText(dir / "stands.geojson", R"({"type": "FeatureCollection", "features": [
{"type": "Feature", "properties": {"stems_per_ha": 2000, "dbh_cm": 20, "species": "beech"},
 "geometry": {"type": "Polygon", "coordinates": [[[20, -10], [30, -10], [30, 10], [20, 10], [20, -10]]]}},
{"type": "Feature", "properties": {"stems_per_ha": 2000, "dbh_cm": 20, "species": null},
 "geometry": {"type": "Polygon", "coordinates": [[[30, -10], [40, -10], [40, 10], [30, 10], [30, -10]]]}}]})");
  testing::WriteText(dir / "scene.toml", kScene + "[forest]\nstands_file = \"stands.geojson\"\n" +
                                             "[forest.species.beech]\nenergy_factor = 1.6\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  ASSERT_EQ(s.stands.size(), 2u);
  EXPECT_EQ(s.stands[0].species, "beech");
  EXPECT_EQ(s.stands[1].species, "");
  ASSERT_FALSE(s.scene.forest.empty());
  for (const Stem& stem : s.scene.forest.stems())
    EXPECT_EQ(stem.species, stem.position_m.x() < 30 ? 0 : -1) << stem.position_m.x();
  EXPECT_TRUE(s.warnings.empty());
}

// model = "drag": a stand's species sets its DragStand's breaking energy; raster_species that of
// the rasters' stands.
TEST(SceneForest, TheDragStandsBreakByTheirSpeciesLaw) {
  const auto dir = testing::FreshDir("scene");
  // 2 x 2 cells of 5 m from (20, -5) to (30, 5): 800 stems/ha of DBH 25 cm, 300 of 40 cm.
  const std::array<double, 6> gt = {20, 5, 0, 5, 0, -5};
  testing::WriteGdalRaster(dir / "density.tif", {{800, 300}, {800, 300}}, gt, 0, -1);
  testing::WriteGdalRaster(dir / "dbh.tif", {{25, 40}, {25, 40}}, gt, 0, -1);
  testing::WriteText(
      dir / "scene.toml",
      kScene +
          "[forest]\nmodel = \"drag\"\nstems_per_ha_raster = \"density.tif\"\n"
          "dbh_raster = \"dbh.tif\"\nraster_species = \"larch\"\n"
          "stands = [{ polygon = [[30, -10], [35, -10], [35, 10], [30, 10]], stems_per_ha = 400, "
          "dbh_cm = 30, species = \"beech\" }, { polygon = [[35, -10], [40, -10], [40, 10], [35, "
          "10]], stems_per_ha = 400, dbh_cm = 30 }]\n" +
          kSpecies);
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  const ForestDrag& drag = s.scene.forest_drag;
  const double e30 = ForestModel{}.BreakingEnergy_J(0.30);
  ASSERT_NE(drag.StandAt(32, 0), nullptr);
  EXPECT_EQ(drag.StandAt(32, 0)->breaking_energy_J, 1.6 * e30);  // beech
  ASSERT_NE(drag.StandAt(38, 0), nullptr);
  EXPECT_EQ(drag.StandAt(38, 0)->breaking_energy_J, e30);  // no species
  ASSERT_NE(drag.StandAt(22, 0), nullptr);
  EXPECT_NEAR(drag.StandAt(22, 0)->breaking_energy_J, 60 * std::pow(25.0, 2.31),
              1e-9 * drag.StandAt(22, 0)->breaking_energy_J);  // larch, the rasters'
  EXPECT_EQ(s.forest_raster_species, "larch");
  ASSERT_EQ(s.stands.size(), 2u);
  EXPECT_EQ(s.stands[0].species, "beech");
  EXPECT_TRUE(s.warnings.empty());
}

// The rocks.csv of a run (as talus simulate writes it), `threads` 1.
std::string RocksCsvOf(const SceneFile& s, const std::string& name) {
  ensemble::EnsembleOptions options;
  options.threads = 1;
  Collect sink;
  ensemble::RunEnsemble(s.scene, s.release, options, &sink);
  std::sort(sink.rocks.begin(), sink.rocks.end(),
            [](const auto& a, const auto& b) { return a.rock < b.rock; });
  const auto path = testing::FreshDir(name) / "rocks.csv";
  RocksCsvWriter csv(path.string(), s.scene, s.release);
  long broken = 0;
  for (const ensemble::RockOutcome& rock : sink.rocks) {
    csv.Write(rock);
    for (const StemHit& h : rock.result.stem_hits) broken += h.broken;
  }
  csv.Commit();
  EXPECT_GT(broken, 0) << "the rocks break stems";
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A species of factor 1 is the forest's law: a scene whose one stand is of that species gives the
// bytes of rocks.csv of the same scene without species.
TEST(SceneForest, ASpeciesOfFactorOneGivesTheRocksOfTheSceneWithoutSpecies) {
  std::string scene = kScene;
  scene.replace(scene.find("seed = 4\n"), 9,
                "seed = 4\nvelocity_m_s = [6, 0, 0]\norientation = \"random\"\n");
  std::string thin = kStand;  // 5 cm stems, which the rocks break
  thin.replace(thin.find("dbh_cm = 30, dbh_sd_cm = 5"), 26, "dbh_cm = 5, dbh_sd_cm = 1");
  std::string of_species = thin;
  of_species.replace(of_species.find(" }]"), 3, ", species = \"spruce\" }]");
  const SceneFile plain = Load(thin, "", scene);
  const SceneFile spruce =
      Load(of_species + "[forest.species.spruce]\nenergy_factor = 1\n", "", scene);
  ASSERT_EQ(spruce.scene.forest.stems().front().species, 0);
  EXPECT_EQ(RocksCsvOf(spruce, "spruce"), RocksCsvOf(plain, "plain"));
}

// model = "drag": the stands on the DEM's nodes (1 m here) as ForestDrag stands of density
// stems_per_ha / 1e4 per m^2, the mean DBH and E_max(DBH) of the model's law; no stems.
TEST(SceneForest, TheDragModelPutsTheStandsOnTheDemGrid) {
  const SceneFile s =
      Load(kStand + "model = \"drag\"\nstem_height_m = 12\nenergy_coefficient_j = 40\n");
  EXPECT_EQ(s.forest_model, "drag");
  EXPECT_FALSE(s.has_forest);
  EXPECT_TRUE(s.scene.forest.empty());
  const ForestDrag& drag = s.scene.forest_drag;
  ASSERT_FALSE(drag.empty());
  EXPECT_EQ(drag.height_m(), 12);
  const DragStand* inside = drag.StandAt(30, 0);
  ASSERT_NE(inside, nullptr);
  EXPECT_DOUBLE_EQ(inside->stems_per_m2, 0.5);
  EXPECT_DOUBLE_EQ(inside->dbh_m, 0.3);
  EXPECT_DOUBLE_EQ(inside->breaking_energy_J, 40 * std::pow(30.0, 2.31));
  EXPECT_EQ(drag.StandAt(45, 0), nullptr);
  EXPECT_EQ(drag.StandAt(30, 12), nullptr);
  // Nodes 20 .. 40 on both axes, less one edge row: GDAL's rasteriser takes a node on a
  // polygon's edge on one side only.
  EXPECT_EQ(s.forest_drag_cells, 20 * 21);
  ASSERT_EQ(s.stands.size(), 1u);
  EXPECT_EQ(s.stands[0].trees, 0);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_HAS(s.warnings[0], "dbh_sd_cm is not used by model = \"drag\"");
  std::string why;
  EXPECT_TRUE(s.scene.IsValid(&why)) << why;
}

// stems_per_ha_raster and dbh_raster: each DEM node takes the raster cell holding it; nodata or
// 0 stems: no forest; a stand polygon lies over the rasters.
TEST(SceneForest, TheDragModelReadsDensityAndDbhRasters) {
  const auto dir = testing::FreshDir("scene");
  // 4 x 2 cells of 5 m from (20, -5) to (40, 5): west to east 800, 0, nodata, 300 stems/ha.
  const std::array<double, 6> gt = {20, 5, 0, 5, 0, -5};
  testing::WriteGdalRaster(dir / "density.tif", {{800, 0, -1, 300}, {800, 0, -1, 300}}, gt, 0, -1);
  testing::WriteGdalRaster(dir / "dbh.tif", {{25, 0, 0, 40}, {25, 0, 0, 40}}, gt, 0, -1);
  const std::string forest =
      "[forest]\nmodel = \"drag\"\nstems_per_ha_raster = \"density.tif\"\n"
      "dbh_raster = \"dbh.tif\"\n";
  testing::WriteText(dir / "scene.toml", kScene + forest);
  SceneFile s = LoadScene((dir / "scene.toml").string());
  const ForestDrag& drag = s.scene.forest_drag;
  const DragStand* west = drag.StandAt(22, 0);
  ASSERT_NE(west, nullptr);
  EXPECT_DOUBLE_EQ(west->stems_per_m2, 0.08);
  EXPECT_DOUBLE_EQ(west->dbh_m, 0.25);
  const DragStand* east = drag.StandAt(38, -4);
  ASSERT_NE(east, nullptr);
  EXPECT_DOUBLE_EQ(east->stems_per_m2, 0.03);
  EXPECT_DOUBLE_EQ(east->dbh_m, 0.40);
  EXPECT_EQ(drag.StandAt(27, 0), nullptr);  // 0 stems
  EXPECT_EQ(drag.StandAt(32, 0), nullptr);  // nodata
  EXPECT_EQ(drag.StandAt(22, 7), nullptr);  // off the rasters
  EXPECT_EQ(drag.stands().size(), 2u);
  testing::WriteText(dir / "scene.toml",
                     kScene + forest +
                         "stands = [{ polygon = [[20, -2], [24, -2], [24, 2], [20, 2]], "
                         "stems_per_ha = 100, dbh_cm = 50 }]\n");
  s = LoadScene((dir / "scene.toml").string());
  EXPECT_DOUBLE_EQ(s.scene.forest_drag.StandAt(22, 0)->dbh_m, 0.5);
  EXPECT_DOUBLE_EQ(s.scene.forest_drag.StandAt(22, -4)->dbh_m, 0.25);
  // A negative density, and a DBH of 0 where there are stems, name the file and the first DEM
  // node (from the south-west) that takes such a cell: (35, 0) and (20, 0) take the northern row.
  testing::WriteGdalRaster(dir / "density.tif", {{800, 0, -1, -300}, {800, 0, -1, 300}}, gt, 0, -1);
  testing::WriteText(dir / "scene.toml", kScene + forest);
  try {
    LoadScene((dir / "scene.toml").string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_HAS(e.what(), "forest.stems_per_ha_raster: ");
    EXPECT_HAS(e.what(), "density.tif: -300 stems per hectare at (35, 0) must be > 0");
  }
  testing::WriteGdalRaster(dir / "density.tif", {{800, 0, -1, 300}, {800, 0, -1, 300}}, gt, 0, -1);
  testing::WriteGdalRaster(dir / "dbh.tif", {{0, 0, 0, 40}, {25, 0, 0, 40}}, gt, 0, -1);
  try {
    LoadScene((dir / "scene.toml").string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_HAS(e.what(), "forest.dbh_raster: ");
    EXPECT_HAS(e.what(), "dbh.tif: DBH 0 cm at (20, 0), where");
  }
  // Rasters off the DEM.
  testing::WriteGdalRaster(dir / "dbh.tif", {{25}}, {1000, 5, 0, 5, 0, -5}, 0, -1);
  try {
    LoadScene((dir / "scene.toml").string());
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_HAS(e.what(), "forest.dbh_raster: ");
    EXPECT_HAS(e.what(), "none of the DEM");
  }
}

TEST(SceneForest, TheDragModelsBadInputIsAnErrorNamingTheKey) {
  EXPECT_HAS(ErrorOf(kStand + "model = \"forest\"\n"),
             "forest.model: unknown forest model 'forest'");
  EXPECT_HAS(ErrorOf("[forest]\nmodel = \"drag\"\n"),
             "forest.model: model = \"drag\" needs stands");
  EXPECT_HAS(
      ErrorOf("[forest]\nmodel = \"drag\"\ntrees = \"trees.csv\"\n", "x_m,y_m,dbh_cm\n30,0,30\n"),
      "forest.trees: model = \"drag\" has no explicit trees");
  EXPECT_HAS(ErrorOf(kStand + "model = \"drag\"\nfriction = 0.3\n"),
             "forest.friction: model = \"drag\" has no explicit trees");
  EXPECT_HAS(ErrorOf(kStand + "model = \"drag\"\nstems_per_ha_raster = \"d.tif\"\n"),
             "forest.stems_per_ha_raster: stems_per_ha_raster and dbh_raster go together");
  EXPECT_HAS(ErrorOf(kStand + "dbh_raster = \"d.tif\"\n"),
             "forest.dbh_raster: dbh_raster is for model = \"drag\"");
  EXPECT_HAS(ErrorOf(kStand + "model = \"drag\"\nstem_height_m = 0\n"), "forest.stem_height_m");
  EXPECT_HAS(ErrorOf(kStand + "model = \"drag\"\n[output]\nrasters = [\"tree_hits\"]\n"),
             "tree_hits counts the impacts on explicit stems: [forest] model = \"drag\" has none");
}

}  // namespace
}  // namespace talus::io
