#include "pointclouds/point_cloud.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <limits>

#include "common/error.hpp"
#include "solver/shapes.hpp"
#include "test_clouds.hpp"

namespace talus::pointclouds {
namespace {

using testing::TempDir;

// The message of the InputError that reading `path` throws ("" when it reads fine).
std::string ReadError(const std::string& path) {
  try {
    ReadPointCloud(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::vector<Eigen::Vector3d> Absolute(const PointCloud& cloud) {
  std::vector<Eigen::Vector3d> p;
  for (const auto& q : cloud.points_m) p.push_back(cloud.offset_m + q);
  return p;
}

const std::vector<Eigen::Vector3d> kPoints = {
    {0, 0, 0}, {1.5, 0, 0}, {0, 2.25, 0}, {0, 0, -3}, {0.125, 0.25, 0.5}};

void ExpectPoints(const PointCloud& cloud, const std::vector<Eigen::Vector3d>& expected,
                  double tol = 0) {
  ASSERT_EQ(cloud.points_m.size(), expected.size()) << cloud.source;
  const auto got = Absolute(cloud);
  for (std::size_t i = 0; i < expected.size(); ++i)
    EXPECT_LE((got[i] - expected[i]).norm(), tol) << cloud.source << " point " << i;
}

TEST(CleanOptions, DefaultsAreValid) {
  std::string why;
  EXPECT_TRUE(CleanOptions{}.IsValid(&why)) << why;
  CleanOptions bad;
  bad.voxel_m = -0.1;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("voxel_m"), std::string::npos) << why;
  // So small that the voxel indices of a metre-sized rock overflow 64-bit integers.
  bad.voxel_m = 1e-30;
  EXPECT_FALSE(bad.IsValid(&why));
  EXPECT_NE(why.find("voxel_m = 1e-30"), std::string::npos) << why;
  for (const auto& [field, set] :
       std::vector<std::pair<std::string, std::function<void(CleanOptions&)>>>{
           {"outlier_neighbours = -1", [](CleanOptions& o) { o.outlier_neighbours = -1; }},
           {"outlier_std_ratio = 0", [](CleanOptions& o) { o.outlier_std_ratio = 0; }},
           {"outlier_spacing_ratio = -1", [](CleanOptions& o) { o.outlier_spacing_ratio = -1; }},
           {"outlier_passes = 0", [](CleanOptions& o) { o.outlier_passes = 0; }}}) {
    CleanOptions o;
    set(o);
    EXPECT_FALSE(o.IsValid(&why)) << field;
    EXPECT_NE(why.find(field), std::string::npos) << why;
  }
  EXPECT_TRUE(CleanOptions::Off().IsValid(&why));
  EXPECT_EQ(CleanOptions::Off().outlier_neighbours, 0);
}

TEST(ReadPointCloud, TextFormatsWithHeadersCommentsAndExtraColumns) {
  TempDir dir;
  const std::string xyz = dir.Write(
      "scan.xyz", "# scanner output\n\n0 0 0 17\n1.5 0 0 17\n0 2.25 0\n0 0 -3\n0.125 0.25 0.5\n");
  const std::string csv = dir.Write(
      "scan.CSV",
      "x,y,z,intensity\r\n0,0,0,1\r\n1.5,0,0,1\r\n0,2.25,0,1\r\n0,0,-3,1\r\n0.125,0.25,0.5,1\r\n");
  const std::string txt =
      dir.Write("scan.txt", "// comment\n0;0;0\n+1.5;0;0\n0;2.25;0\n0;0;-3e0\n0.125;0.25;0.5");
  const std::string pts = dir.Write("rock.pts",
                                    "5\n0 0 0 1 2 3 4\n1.5 0 0 1 2 3 4\n0 2.25 0 1 2 3 4\n0 0 -3 1 "
                                    "2 3 4\n0.125 0.25 0.5 1 2 3 4\n");
  for (const auto& path : {xyz, csv, txt, pts}) ExpectPoints(ReadPointCloud(path), kPoints);
  EXPECT_EQ(ReadPointCloud(xyz).source_lines.front(), 3);
}

TEST(ReadPointCloud, DecimalCommasAreAnErrorNotExtraCoordinates) {
  // "1,5;2,5;3,5" is the point (1.5, 2.5, 3.5) in a European CSV; splitting it at the commas
  // as well would read (1, 5, 2).
  TempDir dir;
  const std::string path = dir.Write("eu.csv", "x;y;z\n1,5;2,5;3,5\n0;0;0\n");
  const std::string why = ReadError(path);
  EXPECT_NE(why.find(path + ":2: expected a point"), std::string::npos) << why;
  // Semicolons alone, and commas alone, still separate.
  ExpectPoints(ReadPointCloud(dir.Write("semi.csv", "1.5; 2.5; 3.5\n")), {{1.5, 2.5, 3.5}});
  ExpectPoints(ReadPointCloud(dir.Write("comma.csv", "1.5, 2.5, 3.5, 7\n")), {{1.5, 2.5, 3.5}});
}

TEST(ReadPointCloud, HeaderCountsTheFileCannotHoldAreRefused) {
  // PCL allocates the points a header announces before it reads them: a 100-byte file claiming
  // 10^9 points took 12 GB and half a minute. 10^7 here, so that the test stays cheap either way.
  TempDir dir;
  const std::string pcd =
      dir.Write("huge.pcd",
                "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 10000000\n"
                "HEIGHT 1\nPOINTS 10000000\nDATA binary\n0123456789ab");
  const std::string ply = dir.Write("huge.ply",
                                    "ply\nformat ascii 1.0\nelement vertex 10000000\nproperty "
                                    "float x\nproperty float y\nproperty float z\nend_header\n"
                                    "0 0 0\n");
  for (const auto& path : {pcd, ply}) {
    const std::string why = ReadError(path);
    EXPECT_NE(why.find(path + ": not a readable"), std::string::npos) << why;
    EXPECT_NE(why.find("announces 10000000 points"), std::string::npos) << why;
  }
}

TEST(ReadPointCloud, PtsCountMustMatch) {
  TempDir dir;
  const std::string path = dir.Write("rock.pts", "4\n0 0 0\n1 0 0\n0 1 0\n");
  const std::string why = ReadError(path);
  EXPECT_NE(why.find(path + ":1:"), std::string::npos) << why;
  EXPECT_NE(why.find("does not match"), std::string::npos) << why;
}

TEST(ReadPointCloud, PcdAsciiAndBinary) {
  TempDir dir;
  const std::string header =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH "
      "5\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 5\n";
  ExpectPoints(
      ReadPointCloud(dir.Write("ascii.pcd", header + "DATA ascii\n" + testing::XyzText(kPoints))),
      kPoints);

  // Binary, single precision, with an extra field between the coordinates.
  std::string binary =
      "VERSION 0.7\nFIELDS x intensity y z\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH "
      "5\nHEIGHT 1\n"
      "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 5\nDATA binary\n";
  for (const auto& p : kPoints) {
    const float values[4] = {static_cast<float>(p.x()), 7.0f, static_cast<float>(p.y()),
                             static_cast<float>(p.z())};
    binary.append(reinterpret_cast<const char*>(values), sizeof values);
  }
  ExpectPoints(ReadPointCloud(dir.Write("binary.pcd", binary)), kPoints);
}

TEST(ReadPointCloud, PlyAsciiDoubleAndBinaryFloat) {
  TempDir dir;
  std::string ascii =
      "ply\nformat ascii 1.0\nelement vertex 5\nproperty double x\nproperty double y\nproperty "
      "double z\n"
      "property uchar red\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& p : kPoints)
    ascii += std::to_string(p.x()) + " " + std::to_string(p.y()) + " " + std::to_string(p.z()) +
             " 200\n";
  ascii += "3 0 1 2\n";
  ExpectPoints(ReadPointCloud(dir.Write("ascii.ply", ascii)), kPoints);

  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  for (const auto& p : kPoints) {
    const float values[3] = {static_cast<float>(p.x()), static_cast<float>(p.y()),
                             static_cast<float>(p.z())};
    binary.append(reinterpret_cast<const char*>(values), sizeof values);
  }
  ExpectPoints(ReadPointCloud(dir.Write("binary.ply", binary)), kPoints);
}

TEST(ReadPointCloud, GeoreferencedCoordinatesAreRecentredWithoutLoss) {
  // LV95-like coordinates: 2.6e6 m. Millimetre details must survive exactly enough.
  TempDir dir;
  const Eigen::Vector3d origin(2600123.456, 1200456.789, 1543.21);
  std::vector<Eigen::Vector3d> points;
  for (const auto& p : kPoints) points.push_back(origin + p);
  for (const std::string name : {"geo.xyz", "geo.pcd", "geo.ply"}) {
    std::string text = testing::XyzText(points);
    if (name == "geo.pcd")
      text =
          "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 5\nHEIGHT "
          "1\nPOINTS 5\nDATA ascii\n" +
          text;
    if (name == "geo.ply")
      text =
          "ply\nformat ascii 1.0\nelement vertex 5\nproperty double x\nproperty double y\nproperty "
          "double z\nend_header\n" +
          text;
    const PointCloud cloud = ReadPointCloud(dir.Write(name, text));
    EXPECT_LT((cloud.offset_m - origin).norm(), 5) << name;
    // Relative to the first point, the geometry is exact to well below a micrometre.
    for (std::size_t i = 0; i < kPoints.size(); ++i)
      EXPECT_NEAR((cloud.points_m[i] - cloud.points_m[0] - kPoints[i]).norm(), 0, 1e-9)
          << name << " point " << i;
  }
}

TEST(ReadPointCloud, BadFilesSayWhatIsWrong) {
  TempDir dir;
  EXPECT_NE(ReadError(dir.File("missing.xyz")).find("no such file"), std::string::npos);
  EXPECT_NE(ReadError(dir.Write("empty.xyz", "")).find("empty"), std::string::npos);
  EXPECT_NE(ReadError(dir.Write("comments.xyz", "# nothing\n\n")).find("no points"),
            std::string::npos);
  EXPECT_NE(ReadError(dir.Write("rock.obj", "v 0 0 0\n")).find("unknown point cloud format '.obj'"),
            std::string::npos);
  const std::string bad_line = dir.Write("bad.xyz", "x y z\n0 0 0\n1 0 zero\n");
  EXPECT_NE(ReadError(bad_line).find(bad_line + ":3: expected a point"), std::string::npos)
      << ReadError(bad_line);
  EXPECT_NE(ReadError(dir.Write("short.csv", "0,0,0\n1,2\n")).find(":2:"), std::string::npos);
  EXPECT_NE(ReadError(dir.Write("garbage.ply", "this is not a ply file\n"))
                .find("not a readable PLY file"),
            std::string::npos);
  EXPECT_NE(
      ReadError(dir.Write("garbage.pcd", "\x01\x02 nonsense\n")).find("not a readable PCD file"),
      std::string::npos);
  std::filesystem::create_directory(dir.File("folder.xyz"));
  EXPECT_NE(ReadError(dir.File("folder.xyz")).find("not a regular file"), std::string::npos);
}

TEST(CleanPointCloud, DropsNonFiniteAndDuplicates) {
  TempDir dir;
  const std::string path =
      dir.Write("nan.xyz", "0 0 0\nnan 1 1\n1 0 0\n0 1 0\n1 0 0\n0 0 1\n1 inf 0\n0 0 0\n");
  PointCloud cloud = ReadPointCloud(path);
  const CleanReport report = CleanPointCloud(CleanOptions{}, &cloud);
  EXPECT_EQ(report.points_in, 8u);
  EXPECT_EQ(report.non_finite, 2u);
  EXPECT_EQ(report.duplicates, 2u);
  EXPECT_EQ(report.points_out, 4u);
  ExpectPoints(cloud, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}});
  EXPECT_EQ(cloud.source_lines, (std::vector<int>{1, 3, 4, 6}));

  // Strict: a non-finite point is an error that names its line.
  CleanOptions strict;
  strict.drop_non_finite = false;
  PointCloud again = ReadPointCloud(path);
  try {
    CleanPointCloud(strict, &again);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ":2: non-finite"), std::string::npos) << e.what();
  }
}

TEST(CleanPointCloud, StatisticalOutlierRemoval) {
  std::mt19937_64 rng(5);
  PointCloud cloud;
  cloud.points_m = testing::BoxInterior(1, 1, 1, 2000, rng);
  cloud.points_m.emplace_back(5, 5, 5);  // a stray return far from the rock
  CleanOptions options;
  options.outlier_neighbours = 8;
  const CleanReport report = CleanPointCloud(options, &cloud);
  EXPECT_GE(report.outliers, 1u);
  EXPECT_LT(report.outliers, 100u);
  for (const auto& p : cloud.points_m) EXPECT_LT(p.norm(), 1.0);
}

// The default cleaning is safe: the clean scans of rocks, random or on a regular grid, lose no
// point (so their hull is unchanged), however dense.
TEST(CleanPointCloud, DefaultsKeepEveryPointOfACleanScan) {
  std::mt19937_64 rng(21);
  std::vector<std::pair<std::string, std::vector<Eigen::Vector3d>>> scans = {
      {"ellipsoid 1:0.7:0.4, 2000", testing::EllipsoidSurface(1.0, 0.7, 0.4, 2000, rng)},
      {"ellipsoid 1:0.7:0.4, 20000", testing::EllipsoidSurface(1.0, 0.7, 0.4, 20000, rng)},
      {"ellipsoid 4:1:0.6, 20000", testing::EllipsoidSurface(2.0, 0.5, 0.3, 20000, rng)},
      {"box surface 2 x 1 x 0.6, 20000", testing::BoxSurface(2, 1, 0.6, 20000, rng)},
      {"box interior and corners", testing::BoxInterior(2, 1, 0.6, 2000, rng)}};
  for (const auto& c : testing::BoxCorners(2, 1, 0.6)) scans.back().second.push_back(c);
  std::vector<Eigen::Vector3d> grid;  // a regular grid: the statistical rule alone drops edges
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j)
      for (int k = 0; k < 20; ++k) grid.emplace_back(0.01 * i, 0.01 * j, 0.01 * k);
  scans.emplace_back("regular grid 20^3", grid);
  for (const auto& [name, points] : scans) {
    PointCloud cloud;
    cloud.points_m = points;
    const CleanReport report = CleanPointCloud(CleanOptions{}, &cloud);
    EXPECT_EQ(report.outliers, 0u) << name;
    EXPECT_EQ(cloud.points_m, points) << name;
  }
  // Without the spacing condition PCL's rule alone drops the grid's corners and edges.
  PointCloud cloud;
  cloud.points_m = grid;
  CleanOptions statistical;
  statistical.outlier_spacing_ratio = 0;
  EXPECT_GT(CleanPointCloud(statistical, &cloud).outliers, 0u);
}

// ... and removes stray returns metres off the rock: 1 % and 5 % of the points.
TEST(CleanPointCloud, DefaultsRemoveFarOutliers) {
  for (const int percent : {1, 5}) {
    std::mt19937_64 rng(22 + percent);
    const auto clean = testing::EllipsoidSurface(1.0, 0.7, 0.4, 10000, rng);
    const auto stray = testing::FarOutliers(100 * percent, 1.5, 10, rng);
    PointCloud cloud;
    cloud.points_m = clean;
    cloud.points_m.insert(cloud.points_m.end(), stray.begin(), stray.end());
    const CleanReport report = CleanPointCloud(CleanOptions{}, &cloud);
    EXPECT_EQ(report.outliers, stray.size()) << percent << " %";
    EXPECT_EQ(cloud.points_m, clean) << percent << " %";
    // One pass is not enough: the far outliers inflate the standard deviation.
    CleanOptions once;
    once.outlier_passes = 1;
    PointCloud again;
    again.points_m = clean;
    again.points_m.insert(again.points_m.end(), stray.begin(), stray.end());
    if (percent == 5) {
      EXPECT_LT(CleanPointCloud(once, &again).outliers, stray.size());
    }
  }
}

TEST(CleanPointCloud, VoxelsKeepOneMeasuredPointEach) {
  PointCloud cloud;
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 20; ++j)
      for (int k = 0; k < 20; ++k)
        cloud.points_m.emplace_back(0.01 * i + 0.005, 0.01 * j + 0.005, 0.01 * k + 0.005);
  const auto original = cloud.points_m;
  CleanOptions options = CleanOptions::Off();
  options.voxel_m = 0.05;
  const CleanReport report = CleanPointCloud(options, &cloud);
  EXPECT_EQ(report.points_out, 64u);  // 4 x 4 x 4 voxels
  EXPECT_EQ(report.downsampled, 8000u - 64u);
  for (const auto& p : cloud.points_m)
    EXPECT_NE(std::find(original.begin(), original.end(), p), original.end());
}

TEST(WritePolyhedronPly, RoundTripsThroughTheReader) {
  TempDir dir;
  const Polyhedron box = MakeBox(1, 2, 3);
  const Eigen::Vector3d offset(2600000.5, 1200000.25, 1500);
  const std::string path = dir.File("hull.ply");
  WritePolyhedronPly(box, offset, path);
  const PointCloud cloud = ReadPointCloud(path);
  std::vector<Eigen::Vector3d> expected;
  for (const auto& v : box.vertices_m) expected.push_back(v + offset);
  ExpectPoints(cloud, expected, 1e-8);
  EXPECT_THROW(WritePolyhedronPly(box, offset, dir.File("no/such/dir/hull.ply")), InputError);
}

}  // namespace
}  // namespace talus::pointclouds
