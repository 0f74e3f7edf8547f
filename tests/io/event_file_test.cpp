// Event files: observation tables by kind, rest positions from vector files in the DEM's CRS, and
// errors before any rock runs.

#include "io/event_file.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

#define EXPECT_HAS(text, part) EXPECT_NE(std::string(text).find(part), std::string::npos) << (text)

std::string ErrorOf(const std::filesystem::path& event) {
  try {
    LoadEvent(event.string());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A 20 x 20 cell DEM of 10 m cells in UTM 32N (EPSG:32632) near Innsbruck, flat, and two runs.
std::filesystem::path MakeEvent(const std::string& name, int dem_epsg) {
  const auto dir = testing::FreshDir(name);
  std::vector<std::vector<double>> rows(20, std::vector<double>(20, 600.0));
  testing::WriteGdalRaster(dir / "dem.tif", rows, {680000, 10, 0, 5240200, 0, -10}, dem_epsg,
                           std::nullopt);
  testing::WriteText(dir / "scene.toml",
                     "[terrain]\ndem = \"dem.tif\"\n[rock]\nshape = { box = [0.5, 0.5, 0.5] }\n"
                     "[release]\nruns = \"runs.csv\"\n");
  testing::WriteText(dir / "runs.csv",
                     "trajectory_id,x_m,y_m\nA,680050,5240150\nB,680100,5240100\n");
  return dir;
}

TEST(LoadEvent, TablesOfEveryKindAndTheirRuns) {
  const auto dir = MakeEvent("kinds", 32632);
  testing::WriteText(dir / "obs.csv",
                     "trajectory_id,x_m,y_m,observed_runout_m,scar_length_m\n"
                     "A,680060,5240100,50,1.5\nB,680120,5240060,44,\n");
  testing::WriteText(dir / "impacts.csv",
                     "trajectory_id,incoming_speed_mps,outgoing_speed_mps\nA,10,5\n");
  testing::WriteText(dir / "event.toml", R"(scene = "scene.toml"
[[observations]]
kind = "runout"
file = "obs.csv"
[[observations]]
kind = "deposits"
file = "obs.csv"
[[observations]]
kind = "scars"
file = "obs.csv"
[[observations]]
kind = "impacts"
file = "impacts.csv"
)");
  const EventFile e = LoadEvent((dir / "event.toml").string());
  EXPECT_EQ(e.observations.scalars.size(), 2u + 1u + 2u);  // runouts, scar (B empty), impact
  EXPECT_EQ(e.observations.deposits.size(), 2u);
  EXPECT_TRUE(e.needs_episodes);
  EXPECT_EQ(e.reference, "table1");
  // The event, two tables (obs.csv once), the scene and its inputs.
  EXPECT_EQ(e.inputs.size(), 3u + e.scene.inputs.size());
  EXPECT_EQ(e.inputs_hash.size(), 16u);
}

TEST(LoadEvent, RestPositionsFromAVectorFileAreReprojectedToTheDem) {
  // The points are stored in WGS 84 (GeoJSON's default CRS); the DEM is in UTM 32N. The positions
  // must arrive in the DEM's coordinates: the reference values come from a direct OGR
  // transformation, to 1 mm.
  const auto dir = MakeEvent("vector", 32632);
  OGRSpatialReference utm, wgs;
  utm.importFromEPSG(32632);
  wgs.importFromEPSG(4326);
  utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  wgs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::unique_ptr<OGRCoordinateTransformation> to_wgs(
      OGRCreateCoordinateTransformation(&utm, &wgs));
  double x = 680060, y = 5240100;
  ASSERT_TRUE(to_wgs->Transform(1, &x, &y));
  char text[512];
  std::snprintf(text, sizeof text,
                R"({"type": "FeatureCollection", "features": [{"type": "Feature",
 "properties": {"trajectory_id": "B", "radius_m": 2.5},
 "geometry": {"type": "Point", "coordinates": [%.12f, %.12f]}}]})",
                x, y);
  testing::WriteText(dir / "deposits.geojson", text);
  testing::WriteText(dir / "event.toml",
                     "scene = \"scene.toml\"\n[[observations]]\nkind = \"deposits\"\nfile = "
                     "\"deposits.geojson\"\n");
  const EventFile e = LoadEvent((dir / "event.toml").string());
  ASSERT_EQ(e.observations.deposits.size(), 1u);
  const auto& d = e.observations.deposits[0];
  EXPECT_EQ(d.run, "B");
  EXPECT_NEAR(d.xy_m.x(), 680060, 1e-3);
  EXPECT_NEAR(d.xy_m.y(), 5240100, 1e-3);
  ASSERT_TRUE(d.radius_m.has_value());
  EXPECT_EQ(*d.radius_m, 2.5);
}

TEST(LoadEvent, ACrsTheDemLacksIsAnError) {
  // A GeoPackage-like CRS (explicit EPSG:31287 in the GeoJSON) over a DEM without CRS.
  const auto dir = MakeEvent("no_crs", 0);
  testing::WriteText(dir / "deposits.geojson",
                     R"({"type": "FeatureCollection", "crs": {"type": "name", "properties":
 {"name": "urn:ogc:def:crs:EPSG::31287"}}, "features": [{"type": "Feature", "properties": {},
 "geometry": {"type": "Point", "coordinates": [680060, 5240100]}}]})");
  testing::WriteText(dir / "event.toml",
                     "scene = \"scene.toml\"\n[[observations]]\nkind = \"deposits\"\nfile = "
                     "\"deposits.geojson\"\n");
  EXPECT_HAS(ErrorOf(dir / "event.toml"),
             "event.toml:4: observations[0].file: " + (dir / "deposits.geojson").string() +
                 " has a CRS but the DEM has none");
}

TEST(LoadEvent, BadEventsNameFileLineAndKey) {
  const auto dir = MakeEvent("bad", 32632);
  testing::WriteText(dir / "obs.csv", "trajectory_id,observed_runout_m\nA,50\nC,3\n");
  const auto write = [&](const std::string& text) {
    testing::WriteText(dir / "event.toml", text);
    return ErrorOf(dir / "event.toml");
  };
  EXPECT_HAS(write("scene = \"scene.toml\"\n[[observations]]\nkind = \"runout\"\n"
                   "file = \"obs.csv\"\n"),
             "obs.csv:3: run 'C' is not a run of the scene");
  EXPECT_HAS(
      write("scene = \"none.toml\"\n[[observations]]\nkind = \"runout\"\nfile = \"obs.csv\"\n"),
      "event.toml:1: scene: ");
  EXPECT_HAS(write("scene = \"scene.toml\"\n"), "observations: missing");
  EXPECT_HAS(write("scene = \"scene.toml\"\nsceen = 1\n[[observations]]\nkind = \"runout\"\n"
                   "file = \"obs.csv\"\n"),
             "event.toml:2: sceen: unknown key (did you mean 'scene'?)");
  EXPECT_HAS(write("scene = \"scene.toml\"\n[[observations]]\nkind = \"runout\"\n"
                   "file = \"nothing.csv\"\n"),
             "event.toml:4: observations[0].file: file not found");
  EXPECT_HAS(write("scene = \"scene.toml\"\nreference = \"table2\"\n[[observations]]\nkind = "
                   "\"runout\"\nfile = \"obs.csv\"\n"),
             "event.toml:2: reference: 'table2': expected \"table1\" or \"none\"");
  testing::WriteText(dir / "empty.csv", "trajectory_id,observed_runout_m\n");
  EXPECT_HAS(write("scene = \"scene.toml\"\n[[observations]]\nkind = \"runout\"\n"
                   "file = \"empty.csv\"\n"),
             "holds no observation");
}

TEST(ReferenceGround, Table1ValuesForBuiltInCategoriesOnly) {
  GroundTable table = GroundTable::BuiltIn();
  bool differs = true;
  ReferenceGround(table, &differs);
  EXPECT_FALSE(differs);
  table.mutable_params(table.IndexOfName("hard")).mu_min = 0.9;
  const int user = table.Set({"scree", 20, GroundParams{0.5, 1.5, 100, 2, 0.3}});
  const GroundTable reference = ReferenceGround(table, &differs);
  EXPECT_TRUE(differs);
  EXPECT_EQ(reference.params(reference.IndexOfName("hard")).mu_min, 0.55);
  EXPECT_EQ(reference.params(user).mu_min, 0.5);  // user categories unchanged
}

}  // namespace
}  // namespace talus::io
