#include "io/vector.hpp"

#include <gtest/gtest.h>

#include "common/error.hpp"
#include "io/scene_file.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

using Kind = ensemble::ReleaseGeometry::Kind;

const char* kGeoJson = R"({"type": "FeatureCollection", "features": [
 {"type": "Feature", "properties": {}, "geometry": {"type": "Point", "coordinates": [5, 1]}},
 {"type": "Feature", "properties": {}, "geometry": {"type": "LineString", "coordinates": [[2, -3], [2, 3]]}},
 {"type": "Feature", "properties": {}, "geometry": {"type": "MultiPolygon", "coordinates":
   [[[[8, -2], [10, -2], [10, 2], [8, 2], [8, -2]]], [[[12, -1], [13, -1], [13, 1], [12, -1]]]]}}
]})";

TEST(ReadReleaseGeometries, GeoJsonPointsLinesAndMultiPolygons) {
  const auto dir = testing::FreshDir("geojson");
  testing::WriteText(dir / "release.geojson", kGeoJson);
  const auto g = ReadReleaseGeometries((dir / "release.geojson").string(), "", "release.file");
  ASSERT_EQ(g.size(), 4u);
  EXPECT_EQ(g[0].kind, Kind::kPoint);
  EXPECT_EQ(g[0].rings[0][0], Eigen::Vector2d(5, 1));
  EXPECT_EQ(g[1].kind, Kind::kLine);
  EXPECT_EQ(g[2].kind, Kind::kPolygon);
  EXPECT_EQ(g[2].rings[0].size(), 4u);  // closing point dropped
  EXPECT_EQ(g[3].kind, Kind::kPolygon);
}

TEST(ReadReleaseGeometries, SceneReleaseFileIsRelativeToTheScene) {
  const auto dir = testing::FreshDir("scene");
  std::filesystem::create_directories(dir / "gis");
  testing::WriteText(dir / "gis" / "release.geojson", kGeoJson);
  testing::WriteText(
      dir / "scene.toml",
      "[terrain]\nplane = { slope_deg = 30, slope_length_m = 20, runout_m = 10, width_m = 20 }\n"
      "[rock]\nshape = { box = [1, 1, 1] }\n[release]\nfile = \"gis/release.geojson\"\nrocks = "
      "3\n");
  const SceneFile s = LoadScene((dir / "scene.toml").string());
  EXPECT_EQ(s.release.releases.size(), 4u);
  EXPECT_EQ(s.release.total_rocks(), 12);
}

TEST(ReadReleaseGeometries, BadFiles) {
  const auto dir = testing::FreshDir("bad");
  EXPECT_THROW(ReadReleaseGeometries((dir / "none.geojson").string(), "", "release.file"),
               InputError);
  testing::WriteText(dir / "empty.geojson", R"({"type": "FeatureCollection", "features": []})");
  try {
    ReadReleaseGeometries((dir / "empty.geojson").string(), "", "release.file");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has no point, line or polygon"), std::string::npos)
        << e.what();
  }
  // A release in a CRS while the DEM has none cannot be placed.
  testing::WriteText(
      dir / "crs.geojson",
      R"({"type": "FeatureCollection", "crs": {"type": "name", "properties": {"name": "urn:ogc:def:crs:EPSG::31287"}},
 "features": [{"type": "Feature", "properties": {}, "geometry": {"type": "Point", "coordinates": [5, 1]}}]})");
  try {
    ReadReleaseGeometries((dir / "crs.geojson").string(), "", "release.file");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the DEM has none"), std::string::npos) << e.what();
  }
}

TEST(ReadReleaseGeometries, ReprojectsToTheDemCrs) {
  const auto dir = testing::FreshDir("reproject");
  // A point given in WGS 84 lon/lat; the DEM is in MGI / Austria Lambert (EPSG:31287).
  testing::WriteText(
      dir / "wgs84.geojson",
      R"({"type": "FeatureCollection", "features": [{"type": "Feature", "properties": {},
 "geometry": {"type": "Point", "coordinates": [11.4, 47.3]}}]})");
  const auto g =
      ReadReleaseGeometries((dir / "wgs84.geojson").string(), testing::Wkt(31287), "release.file");
  ASSERT_EQ(g.size(), 1u);
  // Innsbruck area in Austria Lambert: x about 250 km, y about 370 km (false origin 400 km, 400
  // km).
  EXPECT_GT(g[0].rings[0][0].x(), 200000);
  EXPECT_LT(g[0].rings[0][0].x(), 300000);
  EXPECT_GT(g[0].rings[0][0].y(), 330000);
  EXPECT_LT(g[0].rings[0][0].y(), 400000);
}

}  // namespace
}  // namespace talus::io
