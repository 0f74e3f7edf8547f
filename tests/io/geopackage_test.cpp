#include "io/geopackage.hpp"

#include <gdal_priv.h>
#include <gtest/gtest.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "common/error.hpp"
#include "io/barriers_csv.hpp"
#include "io/evaluation_lines_csv.hpp"
#include "io/rocks_csv.hpp"
#include "io/trajectory_file.hpp"
#include "io/tree_impacts_csv.hpp"
#include "solver/shapes.hpp"
#include "test_files.hpp"

namespace talus::io {
namespace {

// rocks.csv with the real header: rock k ends at (100 + k, 200 + k, 300 + k).
std::string RocksCsv(int rocks) {
  std::string text = std::string(RocksCsvWriter::Header()) + "\n";
  for (int k = 0; k < rocks; ++k) {
    const std::string c = std::to_string(k);
    text += c + ",0,\"run, " + c + "\",7," + (k == 0 ? "rest" : "left_domain") + ",10" + c + ",20" +
            c + ",30" + c + ",12.5,13,2,3.5,4000,0.5,6,0,,100,0,0,0,30,hard,\n";
  }
  return text;
}

struct Dataset {
  explicit Dataset(const std::string& path)
      : d(static_cast<GDALDataset*>(
            GDALOpenEx(path.c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr))) {}
  ~Dataset() {
    if (d) GDALClose(d);
  }
  GDALDataset* d;
};

TEST(RocksGeoPackage, EndPointsWithEveryColumnAndPathsInTheDemsCrs) {
  const auto dir = testing::FreshDir("gpkg");
  testing::WriteText(dir / "rocks.csv", RocksCsv(3));
  {
    TrajectoryWriter writer((dir / "t.h5").string(), MakeRockShape(MakeBox(1, 1, 1), 2000), "");
    for (long rock = 0; rock < 3; ++rock) {
      StoredTrajectory t;
      t.mass_kg = 2000;
      for (int k = 0; k <= rock + 1; ++k) {
        ensemble::TrajectorySample s;
        s.position_m = Eigen::Vector3d(k, 10.0 * rock, -k);
        s.orientation = Eigen::Quaterniond::Identity();
        s.velocity_m_s.setZero();
        s.angular_velocity_rad_s.setZero();
        t.samples.push_back(s);
      }
      writer.Write(rock, t);
    }
    writer.Commit();
  }
  const std::string path = (dir / "rocks.gpkg").string();
  WriteRocksGeoPackage(path, (dir / "rocks.csv").string(), (dir / "t.h5").string(),
                       testing::Wkt(2056));
  RegisterGdal();
  Dataset gpkg(path);
  ASSERT_NE(gpkg.d, nullptr);
  OGRLayer* ends = gpkg.d->GetLayerByName("end_points");
  ASSERT_NE(ends, nullptr);
  EXPECT_EQ(ends->GetFeatureCount(), 3);
  ASSERT_NE(ends->GetSpatialRef(), nullptr);
  EXPECT_STREQ(ends->GetSpatialRef()->GetAuthorityCode(nullptr), "2056");
  // One field per column of rocks.csv.
  const std::string header = RocksCsvWriter::Header();
  EXPECT_EQ(ends->GetLayerDefn()->GetFieldCount(),
            static_cast<int>(std::count(header.begin(), header.end(), ',') + 1));
  ends->ResetReading();
  std::unique_ptr<OGRFeature> second;
  for (int k = 0; k < 2; ++k) second.reset(ends->GetNextFeature());
  ASSERT_NE(second, nullptr);
  const auto* point = second->GetGeometryRef()->toPoint();
  EXPECT_EQ(point->getX(), 101);
  EXPECT_EQ(point->getY(), 201);
  EXPECT_EQ(point->getZ(), 301);
  EXPECT_EQ(second->GetFieldAsInteger64("rock"), 1);
  EXPECT_STREQ(second->GetFieldAsString("run"), "run, 1");
  EXPECT_STREQ(second->GetFieldAsString("end"), "left_domain");
  EXPECT_DOUBLE_EQ(second->GetFieldAsDouble("max_kinetic_energy_j"), 4000);
  EXPECT_TRUE(second->IsFieldNull(second->GetFieldIndex("block")));  // empty: null

  OGRLayer* paths = gpkg.d->GetLayerByName("paths");
  ASSERT_NE(paths, nullptr);
  EXPECT_EQ(paths->GetFeatureCount(), 3);
  paths->ResetReading();
  std::unique_ptr<OGRFeature> line;
  for (int k = 0; k < 3; ++k) line.reset(paths->GetNextFeature());
  const auto* string = line->GetGeometryRef()->toLineString();
  ASSERT_EQ(string->getNumPoints(), 4);  // rock 2: samples k = 0 .. 3
  EXPECT_EQ(string->getX(3), 3);
  EXPECT_EQ(string->getY(3), 20);
  EXPECT_EQ(string->getZ(3), -3);
  EXPECT_EQ(line->GetFieldAsInteger64("rock"), 2);
}

TEST(RocksGeoPackage, SameRocksSameBytesAndLocalMetresForThePlane) {
  const auto dir = testing::FreshDir("bytes");
  testing::WriteText(dir / "rocks.csv", RocksCsv(4));
  const std::string a = (dir / "a.gpkg").string(), b = (dir / "b.gpkg").string();
  WriteRocksGeoPackage(a, (dir / "rocks.csv").string(), "", "");
  WriteRocksGeoPackage(b, (dir / "rocks.csv").string(), "", "");
  std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
  const std::string bytes_a((std::istreambuf_iterator<char>(fa)), {});
  const std::string bytes_b((std::istreambuf_iterator<char>(fb)), {});
  EXPECT_FALSE(bytes_a.empty());
  EXPECT_EQ(bytes_a, bytes_b);
  Dataset gpkg(a);
  ASSERT_NE(gpkg.d, nullptr);
  EXPECT_EQ(gpkg.d->GetLayerByName("paths"), nullptr);  // no trajectories: no paths
  // Local metres: an engineering CRS, not taken for longitude and latitude.
  const OGRSpatialReference* srs = gpkg.d->GetLayerByName("end_points")->GetSpatialRef();
  ASSERT_NE(srs, nullptr);
  EXPECT_TRUE(srs->IsLocal());
  EXPECT_FALSE(srs->IsGeographic());
  EXPECT_EQ(srs->GetLinearUnits(nullptr), 1.0);
  // One default QGIS style per layer, as dated as the rest of the file.
  OGRLayer* styles = gpkg.d->GetLayerByName("layer_styles");
  ASSERT_NE(styles, nullptr);
  EXPECT_EQ(styles->GetGeomType(), wkbNone);
  ASSERT_EQ(styles->GetFeatureCount(), 1);
  const std::unique_ptr<OGRFeature> style(styles->GetNextFeature());
  EXPECT_STREQ(style->GetFieldAsString("f_table_name"), "end_points");
  EXPECT_STREQ(style->GetFieldAsString("f_geometry_column"), "geom");
  EXPECT_EQ(style->GetFieldAsInteger("useAsDefault"), 1);
  EXPECT_STREQ(style->GetFieldAsString("update_time"), "2000/01/01 00:00:00+00");
  EXPECT_NE(std::string(style->GetFieldAsString("styleQML")).find("attr=\"max_kinetic_energy_j\""),
            std::string::npos);
}

TEST(RocksGeoPackage, ABadRocksCsvIsAnErrorAndLeavesNoFile) {
  const auto dir = testing::FreshDir("bad");
  std::string text = RocksCsv(2);
  text.replace(text.rfind(",101,"), 5, ",1o1,");
  testing::WriteText(dir / "rocks.csv", text);
  const std::string path = (dir / "rocks.gpkg").string();
  EXPECT_THROW(WriteRocksGeoPackage(path, (dir / "rocks.csv").string(), "", ""), InputError);
  EXPECT_FALSE(std::filesystem::exists(path));
}

// Evaluation lines: one 3-D point per row of evaluation_lines.csv, every column a field.
TEST(RocksGeoPackage, EvaluationCrossingsArePointsWithEveryColumn) {
  const auto dir = testing::FreshDir("crossings");
  testing::WriteText(dir / "rocks.csv", RocksCsv(3));
  testing::WriteText(dir / "lines.csv",
                     std::string(EvaluationLinesCsvWriter::Header()) +
                         "\n\"net, lower\",0,0,\"run, 0\",1.5,11,22,33,4,1000,250,1250,0.75,0,3\n"
                         "net,2,0,\"run, 2\",2.5,12,23,34,5,2000,250,2250,0.5,0.25,1\n");
  const std::string path = (dir / "rocks.gpkg").string();
  WriteRocksGeoPackage(path, (dir / "rocks.csv").string(), "", "", (dir / "lines.csv").string());
  RegisterGdal();
  Dataset gpkg(path);
  ASSERT_NE(gpkg.d, nullptr);
  OGRLayer* crossings = gpkg.d->GetLayerByName("evaluation_crossings");
  ASSERT_NE(crossings, nullptr);
  EXPECT_EQ(crossings->GetFeatureCount(), 2);
  EXPECT_EQ(crossings->GetLayerDefn()->GetFieldCount(), 15);
  crossings->ResetReading();
  const std::unique_ptr<OGRFeature> first(crossings->GetNextFeature());
  ASSERT_NE(first, nullptr);
  EXPECT_STREQ(first->GetFieldAsString("line"), "net, lower");
  EXPECT_EQ(first->GetFieldAsInteger64("crossings"), 3);
  EXPECT_DOUBLE_EQ(first->GetFieldAsDouble("energy_J"), 1250);
  const auto* point = first->GetGeometryRef()->toPoint();
  EXPECT_DOUBLE_EQ(point->getX(), 11);
  EXPECT_DOUBLE_EQ(point->getY(), 22);
  EXPECT_DOUBLE_EQ(point->getZ(), 33);
  // Without the file: no such layer.
  WriteRocksGeoPackage(path, (dir / "rocks.csv").string(), "", "");
  Dataset plain(path);
  EXPECT_EQ(plain.d->GetLayerByName("evaluation_crossings"), nullptr);
}

// Barriers: one 3-D point per row of barriers.csv at the crossing, every column a field.
TEST(RocksGeoPackage, BarrierImpactsArePointsWithEveryColumn) {
  const auto dir = testing::FreshDir("barrier_impacts");
  testing::WriteText(dir / "rocks.csv", RocksCsv(3));
  testing::WriteText(dir / "barriers.csv",
                     std::string(BarriersCsvWriter::Header()) +
                         "\nnet,flexible_net,1,0,\"run, 1\",stopped,2.5,11,22,33,4,1000,250,1250,"
                         "0.5,0.9,0\n");
  const std::string path = (dir / "rocks.gpkg").string();
  WriteRocksGeoPackage(path, (dir / "rocks.csv").string(), "", "", "",
                       (dir / "barriers.csv").string());
  RegisterGdal();
  Dataset gpkg(path);
  ASSERT_NE(gpkg.d, nullptr);
  OGRLayer* impacts = gpkg.d->GetLayerByName("barrier_impacts");
  ASSERT_NE(impacts, nullptr);
  EXPECT_EQ(impacts->GetFeatureCount(), 1);
  EXPECT_EQ(impacts->GetLayerDefn()->GetFieldCount(), 17);
  impacts->ResetReading();
  const std::unique_ptr<OGRFeature> first(impacts->GetNextFeature());
  ASSERT_NE(first, nullptr);
  EXPECT_STREQ(first->GetFieldAsString("outcome"), "stopped");
  EXPECT_EQ(first->GetFieldAsInteger64("rock"), 1);
  EXPECT_DOUBLE_EQ(first->GetFieldAsDouble("energy_J"), 1250);
  EXPECT_DOUBLE_EQ(first->GetGeometryRef()->toPoint()->getZ(), 33);
  EXPECT_EQ(gpkg.d->GetLayerByName("evaluation_crossings"), nullptr);
}

// The scene on the map: a point, a line and a polygon with a hole as release layers (index, name,
// rocks), the evaluation lines and the barriers with their attributes, at the coordinates given.
TEST(RocksGeoPackage, ReleasesEvaluationLinesAndBarriersAreLayers) {
  const auto dir = testing::FreshDir("scene_layers");
  testing::WriteText(dir / "rocks.csv", RocksCsv(2));
  ensemble::ReleaseSpec release;
  using Kind = ensemble::ReleaseGeometry::Kind;
  release.releases.push_back({Kind::kPoint, {{{1, 2}}}});
  release.releases.push_back({Kind::kLine, {{{0, 0}, {10, 0}, {10, 5}}}});
  release.releases.push_back(
      {Kind::kPolygon, {{{0, 0}, {8, 0}, {8, 8}, {0, 8}}, {{2, 2}, {4, 2}, {4, 4}, {2, 4}}}});
  release.SetRocksPerRelease(3);
  const std::vector<ensemble::EvaluationLine> lines = {{"upper", {{0, 20}, {30, 20}}}};
  Barrier net;
  net.name = "net";
  net.vertices_m = {{0, 30}, {15, 31}};
  net.height_m = 4;
  net.capacity_J = 5e5;
  const std::vector<Barrier> barriers = {net};
  const std::string path = (dir / "scene.gpkg").string();
  WriteRocksGeoPackage(path, (dir / "rocks.csv").string(), "", "", "", "",
                       GeoPackageScene{&release, &lines, &barriers});
  Dataset gpkg(path);
  ASSERT_NE(gpkg.d, nullptr);
  for (const char* name : {"release_points", "release_lines", "release_polygons"}) {
    OGRLayer* layer = gpkg.d->GetLayerByName(name);
    ASSERT_NE(layer, nullptr) << name;
    EXPECT_EQ(layer->GetFeatureCount(), 1) << name;
  }
  OGRLayer* polygons = gpkg.d->GetLayerByName("release_polygons");
  std::unique_ptr<OGRFeature> polygon(polygons->GetNextFeature());
  EXPECT_EQ(polygon->GetFieldAsInteger64("release"), 2);
  EXPECT_EQ(polygon->GetFieldAsInteger64("rocks"), 3);
  const auto* shape = polygon->GetGeometryRef()->toPolygon();
  EXPECT_EQ(shape->getNumInteriorRings(), 1);
  EXPECT_DOUBLE_EQ(shape->get_Area(), 64 - 4);
  std::unique_ptr<OGRFeature> line(gpkg.d->GetLayerByName("release_lines")->GetNextFeature());
  EXPECT_DOUBLE_EQ(line->GetGeometryRef()->toLineString()->get_Length(), 15);
  std::unique_ptr<OGRFeature> upper(gpkg.d->GetLayerByName("evaluation_lines")->GetNextFeature());
  EXPECT_STREQ(upper->GetFieldAsString("name"), "upper");
  std::unique_ptr<OGRFeature> b(gpkg.d->GetLayerByName("barriers")->GetNextFeature());
  EXPECT_STREQ(b->GetFieldAsString("name"), "net");
  EXPECT_STREQ(b->GetFieldAsString("type"), "flexible_net");
  EXPECT_EQ(b->GetFieldAsDouble("height_m"), 4);
  EXPECT_EQ(b->GetFieldAsDouble("capacity_kj"), 500);
  // A run table's runs are points; no layer for kinds the scene does not have.
  ensemble::ReleaseSpec runs;
  for (const auto& [id, x, y] : {std::tuple{"r1", 5.0, 6.0}, std::tuple{"r2", 7.0, 8.0}}) {
    ensemble::ReleaseRun run;
    run.id = id;
    run.xy_m = {x, y};
    runs.runs.push_back(run);
  }
  const std::string path2 = (dir / "runs.gpkg").string();
  WriteRocksGeoPackage(path2, (dir / "rocks.csv").string(), "", "", "", "",
                       GeoPackageScene{&runs, nullptr, nullptr});
  Dataset runs_gpkg(path2);
  OGRLayer* points = runs_gpkg.d->GetLayerByName("release_points");
  ASSERT_NE(points, nullptr);
  EXPECT_EQ(points->GetFeatureCount(), 2);
  std::unique_ptr<OGRFeature> second(points->GetFeature(2));
  ASSERT_NE(second, nullptr);
  EXPECT_STREQ(second->GetFieldAsString("name"), "r2");
  EXPECT_EQ(runs_gpkg.d->GetLayerByName("release_polygons"), nullptr);
  EXPECT_EQ(runs_gpkg.d->GetLayerByName("barriers"), nullptr);
}

// With explicit trees: layer `trees`, every stem a 3-D point at its foot with its DBH, breaking
// energy (38.7 DBH[cm]^2.31 J by default) and the rows of tree_impacts.csv summed per stem.
TEST(RocksGeoPackage, TreesAreALayerWithTheirDbhHitsAndBreakages) {
  const auto dir = testing::FreshDir("trees");
  testing::WriteText(dir / "rocks.csv", RocksCsv(3));
  const Forest forest({Stem{{10, 20}, 0.30, 5}, Stem{{11, 21}, 0.20, 6}, Stem{{12, 22}, 0.45, 7}},
                      ForestModel{});
  // Header of the writer; tree 2 hit by rocks 0 (twice, held) and 1 (broken), tree 0 by rock 2.
  testing::WriteText(dir / "tree_impacts.csv",
                     std::string(TreeImpactsCsvWriter::Header()) +
                         "\n2,0,0,r,12,22,45,2,1.5,12,22,8,300000,250000,0,"
                         "\n2,1,0,r,12,22,45,1,1.7,12,22,8,900000,150000,1,"
                         "\n0,2,0,r,10,20,30,1,2.0,10,20,6,50000,50000,0,\n");
  const std::string path = (dir / "rocks.gpkg").string();
  WriteRocksGeoPackage(
      path, (dir / "rocks.csv").string(), "", testing::Wkt(31287), "", "",
      GeoPackageScene{nullptr, nullptr, nullptr, &forest, (dir / "tree_impacts.csv").string()});
  Dataset gpkg(path);
  ASSERT_NE(gpkg.d, nullptr);
  OGRLayer* trees = gpkg.d->GetLayerByName("trees");
  ASSERT_NE(trees, nullptr);
  EXPECT_EQ(trees->GetFeatureCount(), 3);
  ASSERT_NE(trees->GetSpatialRef(), nullptr);
  EXPECT_STREQ(trees->GetSpatialRef()->GetAuthorityCode(nullptr), "31287");
  struct Expected {
    double x, y, z, dbh_cm;
    long rocks, impacts, broken;
    double absorbed_kj;
  };
  const Expected expected[] = {
      {10, 20, 5, 30, 1, 1, 0, 50}, {11, 21, 6, 20, 0, 0, 0, 0}, {12, 22, 7, 45, 2, 3, 1, 400}};
  for (long k = 0; k < 3; ++k) {
    SCOPED_TRACE(k);
    std::unique_ptr<OGRFeature> f(trees->GetNextFeature());
    ASSERT_NE(f, nullptr);
    const Expected& e = expected[k];
    EXPECT_EQ(f->GetFieldAsInteger64("tree"), k);
    EXPECT_DOUBLE_EQ(f->GetFieldAsDouble("dbh_cm"), e.dbh_cm);
    EXPECT_NEAR(f->GetFieldAsDouble("breaking_energy_kj"), 38.7 * std::pow(e.dbh_cm, 2.31) / 1000,
                1e-9);
    EXPECT_EQ(f->GetFieldAsInteger64("rocks_hit"), e.rocks);
    EXPECT_EQ(f->GetFieldAsInteger64("impacts"), e.impacts);
    EXPECT_EQ(f->GetFieldAsInteger64("broken"), e.broken);
    EXPECT_DOUBLE_EQ(f->GetFieldAsDouble("absorbed_kj"), e.absorbed_kj);
    const OGRPoint* p = f->GetGeometryRef()->toPoint();
    EXPECT_EQ(p->getX(), e.x);
    EXPECT_EQ(p->getY(), e.y);
    EXPECT_EQ(p->getZ(), e.z);
  }
  // No layer without a forest; a row naming a tree the forest lacks is an error naming the line.
  const std::string none = (dir / "none.gpkg").string();
  WriteRocksGeoPackage(none, (dir / "rocks.csv").string(), "", "");
  Dataset without(none);
  EXPECT_EQ(without.d->GetLayerByName("trees"), nullptr);
  testing::WriteText(dir / "tree_impacts.csv", std::string(TreeImpactsCsvWriter::Header()) +
                                                   "\n3,0,0,r,12,22,45,2,1.5,12,22,8,3,2,0,\n");
  try {
    WriteRocksGeoPackage(
        (dir / "bad.gpkg").string(), (dir / "rocks.csv").string(), "", "", "", "",
        GeoPackageScene{nullptr, nullptr, nullptr, &forest, (dir / "tree_impacts.csv").string()});
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tree_impacts.csv:2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no tree 3 in the forest of 3 trees"), std::string::npos)
        << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "bad.gpkg"));
}

}  // namespace
}  // namespace talus::io
