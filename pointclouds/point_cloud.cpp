#include "pointclouds/point_cloud.hpp"

#include <dlfcn.h>
#include <pcl/PCLPointCloud2.h>
#include <pcl/console/print.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "pointclouds/convex_hull.hpp"
#include "pointclouds/pcl_files.hpp"

namespace talus::pointclouds {
namespace {

std::string Lowercase(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

// Silences PCL's console (it prints its own errors to stderr) while a reader or filter runs;
// failures are reported as InputError instead.
class QuietPcl {
 public:
  QuietPcl() : previous_(pcl::console::getVerbosityLevel()) {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  }
  ~QuietPcl() { pcl::console::setVerbosityLevel(previous_); }
  QuietPcl(const QuietPcl&) = delete;
  QuietPcl& operator=(const QuietPcl&) = delete;

 private:
  pcl::console::VERBOSITY_LEVEL previous_;
};

// Shifts the points by the centre of the bounding box of the finite ones.
void Recentre(PointCloud& cloud) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const auto& p : cloud.points_m) {
    if (!p.allFinite()) continue;
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if (!lo.allFinite()) return;
  cloud.offset_m = 0.5 * (lo + hi);
  for (auto& p : cloud.points_m) p -= cloud.offset_m;
}

// Parses a whole token as a double ("nan" and "inf" included; a leading '+' is allowed).
bool ParseDouble(std::string_view token, double* value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  if (token.empty()) return false;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), *value);
  return ec == std::errc() && end == token.data() + token.size();
}

bool ParseCount(std::string_view token, long long* value) {
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), *value);
  return ec == std::errc() && end == token.data() + token.size() && *value >= 0;
}

// Fields separated by blanks, commas or semicolons; on a line with a semicolon, commas are not
// separators (they may be decimal commas, "1,5;2,5;3,5", which must not read as 1, 5, 2).
std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  const bool semicolons = line.find(';') != std::string_view::npos;
  auto separator = [semicolons](char c) {
    return c == ' ' || c == '\t' || c == ';' || (c == ',' && !semicolons);
  };
  while (i < line.size()) {
    while (i < line.size() && separator(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !separator(line[i])) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

// Plain text: XYZ, CSV, TXT, and RAMMS-style PTS with optional point-count lines.
PointCloud ReadTextPoints(const std::string& path, bool pts) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the file for reading");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();

  PointCloud cloud;
  cloud.source = path;
  bool header_seen = false;
  long long announced = -1;  // points announced by the last PTS count line
  std::size_t block_start = 0;
  int announced_line = 0;
  auto check_block = [&]() {
    const std::size_t found = cloud.points_m.size() - block_start;
    if (announced >= 0 && found != static_cast<std::size_t>(announced)) {
      std::ostringstream msg;
      msg << path << ":" << announced_line << ": the point count " << announced
          << " announced here does not match the " << found << " points that follow";
      throw InputError(msg.str());
    }
  };

  int line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    std::string_view line(text.data() + pos, end - pos);
    pos = end + 1;
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    const std::vector<std::string_view> fields = SplitFields(line);
    if (fields.empty() || fields[0].starts_with("#") || fields[0].starts_with("//")) continue;

    long long count = 0;
    if (pts && fields.size() == 1 && ParseCount(fields[0], &count)) {
      check_block();
      announced = count;
      announced_line = line_no;
      block_start = cloud.points_m.size();
      continue;
    }
    Eigen::Vector3d p;
    const bool numeric = fields.size() >= 3 && ParseDouble(fields[0], &p.x()) &&
                         ParseDouble(fields[1], &p.y()) && ParseDouble(fields[2], &p.z());
    if (!numeric) {
      // One line of column names may precede the first point.
      if (cloud.points_m.empty() && !header_seen && announced < 0) {
        header_seen = true;
        continue;
      }
      std::ostringstream msg;
      msg << path << ":" << line_no << ": expected a point (x y z numbers), found '"
          << line.substr(0, 60) << (line.size() > 60 ? "...'" : "'");
      throw InputError(msg.str());
    }
    cloud.points_m.push_back(p);
    cloud.source_lines.push_back(line_no);
  }
  check_block();
  return cloud;
}

// Reads one numeric field of a PCL binary blob as a double.
double FieldValue(const std::uint8_t* at, std::uint8_t datatype) {
  auto get = [at](auto zero) {
    decltype(zero) v;
    std::memcpy(&v, at, sizeof v);
    return static_cast<double>(v);
  };
  switch (datatype) {
    case pcl::PCLPointField::INT8:
      return get(std::int8_t{});
    case pcl::PCLPointField::UINT8:
      return get(std::uint8_t{});
    case pcl::PCLPointField::INT16:
      return get(std::int16_t{});
    case pcl::PCLPointField::UINT16:
      return get(std::uint16_t{});
    case pcl::PCLPointField::INT32:
      return get(std::int32_t{});
    case pcl::PCLPointField::UINT32:
      return get(std::uint32_t{});
    case pcl::PCLPointField::FLOAT32:
      return get(float{});
    case pcl::PCLPointField::FLOAT64:
      return get(double{});
    default:
      return std::numeric_limits<double>::quiet_NaN();
  }
}

// Bytes of one binary PLY scalar type (0 for a type it does not know).
std::size_t PlyTypeSize(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
      type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

// What is wrong with the header of a PCD or PLY file ("" when it looks complete). PCL's PCD
// reader can crash on files that are not PCD at all, so they never reach it; and PCL allocates
// the points a header announces before reading them, so a count that the rest of the file
// cannot hold (binary: bytes per point; ASCII: at least one byte per value) is refused first.
std::string HeaderProblem(const std::string& path, bool pcd) {
  std::ifstream in(path, std::ios::binary);
  std::string line;
  unsigned long long points = 0, point_bytes = 0, values = 0;
  bool binary = false, check = false;
  if (!pcd) {
    if (!std::getline(in, line) || !line.starts_with("ply")) return "it does not start with 'ply'";
    bool in_vertex = false;
    for (int n = 0; n < 1000 && std::getline(in, line); ++n) {
      std::istringstream words(line);
      std::string keyword, a, b;
      words >> keyword >> a >> b;
      if (keyword == "end_header") break;
      if (keyword == "format") binary = a != "ascii";
      if (keyword == "element") {
        in_vertex = a == "vertex";
        if (in_vertex) check = static_cast<bool>(std::istringstream(b) >> points);
      }
      if (keyword == "property" && in_vertex) {
        const std::size_t size = PlyTypeSize(a);
        if (size == 0) check = false;  // a list or an unknown type: no fixed size
        point_bytes += size;
        ++values;
      }
    }
  } else {
    std::vector<std::string> missing = {"FIELDS", "SIZE", "TYPE", "WIDTH", "POINTS", "DATA"};
    std::vector<unsigned long long> sizes, counts;
    for (int n = 0; n < 64 && std::getline(in, line); ++n) {
      std::istringstream words(line);
      std::string keyword;
      words >> keyword;
      std::erase(missing, keyword);
      unsigned long long number = 0;
      if (keyword == "SIZE")
        while (words >> number) sizes.push_back(number);
      if (keyword == "COUNT")
        while (words >> number) counts.push_back(number);
      if (keyword == "POINTS") check = static_cast<bool>(words >> points);
      if (keyword == "DATA") {
        std::string kind;
        words >> kind;
        binary = kind == "binary";
        if (kind != "ascii" && kind != "binary") check = false;  // binary_compressed
        break;
      }
    }
    if (!missing.empty()) return "no " + missing.front() + " line in its header";
    if (counts.empty()) counts.assign(sizes.size(), 1);
    if (counts.size() != sizes.size()) check = false;
    for (std::size_t k = 0; k < sizes.size() && k < counts.size(); ++k) {
      point_bytes += sizes[k] * counts[k];
      values += counts[k];
    }
  }
  const std::streamoff header = in ? static_cast<std::streamoff>(in.tellg()) : -1;
  std::error_code ec;
  const auto file_bytes = std::filesystem::file_size(path, ec);
  if (!check || header < 0 || ec) return "";
  const unsigned long long data_bytes = file_bytes - static_cast<unsigned long long>(header);
  const unsigned long long per_point = binary ? point_bytes : values;
  if (per_point > 0 && points > data_bytes / per_point)
    return "its header announces " + std::to_string(points) + " points, more than the " +
           std::to_string(data_bytes) + " bytes after it can hold";
  return "";
}

// PCL's PCD and PLY readers: the module talus_pcl_files (pcl_files.hpp), loaded on first use.
decltype(&TalusLoadPclFile) PclFileReader() {
  static const auto reader = [] {
    void* module = dlopen(TALUS_PCL_FILES_MODULE, RTLD_NOW | RTLD_LOCAL);
    void* symbol = module ? dlsym(module, "TalusLoadPclFile") : nullptr;
    if (!symbol)
      throw std::runtime_error(std::string("cannot load PCL's PCD and PLY readers: ") + dlerror());
    return reinterpret_cast<decltype(&TalusLoadPclFile)>(symbol);
  }();
  return reader;
}

// PCD and PLY through PCL, into a PCLPointCloud2 so that double-precision fields stay double.
PointCloud ReadPclPoints(const std::string& path, bool pcd) {
  const char* format = pcd ? "PCD" : "PLY";
  const std::string problem = HeaderProblem(path, pcd);
  if (!problem.empty())
    throw InputError(path + ": not a readable " + format + " file (" + problem + ")");
  decltype(&TalusLoadPclFile) load = nullptr;
  try {
    load = PclFileReader();
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": " + e.what() + " (the module " TALUS_PCL_FILES_MODULE
                             " of the build is needed to read PCD and PLY files)");
  }
  pcl::PCLPointCloud2 blob;
  int status = -1;
  try {
    QuietPcl quiet;
    status = load(path.c_str(), pcd, &blob);
  } catch (const std::exception& e) {
    throw InputError(path + ": not a readable " + format + " file (" + e.what() + ")");
  }
  if (status < 0)
    throw InputError(path + ": not a readable " + format + " file (PCL could not parse it)");

  const pcl::PCLPointField* xyz[3] = {nullptr, nullptr, nullptr};
  for (const auto& field : blob.fields)
    for (int k = 0; k < 3; ++k)
      if (field.name == std::string(1, static_cast<char>('x' + k))) xyz[k] = &field;
  if (!xyz[0] || !xyz[1] || !xyz[2])
    throw InputError(path + ": the " + format + " file has no x, y, z fields");

  PointCloud cloud;
  cloud.source = path;
  const std::size_t n = static_cast<std::size_t>(blob.width) * blob.height;
  if (blob.data.size() < n * blob.point_step)
    throw InputError(path + ": the " + format + " file is truncated");
  cloud.points_m.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t* point = blob.data.data() + i * blob.point_step;
    for (int k = 0; k < 3; ++k)
      cloud.points_m[i][k] = FieldValue(point + xyz[k]->offset, xyz[k]->datatype);
  }
  return cloud;
}

// Keeps the points whose flag is set, in order, with their source lines.
void Compact(const std::vector<char>& keep, PointCloud& cloud) {
  std::size_t out = 0;
  const bool lines = !cloud.source_lines.empty();
  for (std::size_t i = 0; i < cloud.points_m.size(); ++i) {
    if (!keep[i]) continue;
    cloud.points_m[out] = cloud.points_m[i];
    if (lines) cloud.source_lines[out] = cloud.source_lines[i];
    ++out;
  }
  cloud.points_m.resize(out);
  if (lines) cloud.source_lines.resize(out);
}

std::size_t DropNonFinite(bool allowed, PointCloud& cloud) {
  std::vector<char> keep(cloud.points_m.size(), 1);
  std::size_t dropped = 0;
  for (std::size_t i = 0; i < cloud.points_m.size(); ++i) {
    if (cloud.points_m[i].allFinite()) continue;
    if (!allowed) {
      std::ostringstream msg;
      msg << cloud.source << ":";
      if (cloud.source_lines.empty())
        msg << " point " << i + 1;
      else
        msg << cloud.source_lines[i];
      msg << ": non-finite coordinates (" << (cloud.points_m[i] + cloud.offset_m).transpose()
          << ")";
      throw InputError(msg.str());
    }
    keep[i] = 0;
    ++dropped;
  }
  Compact(keep, cloud);
  return dropped;
}

std::size_t DropDuplicates(PointCloud& cloud) {
  const auto& p = cloud.points_m;
  std::vector<std::size_t> order(p.size());
  std::iota(order.begin(), order.end(), 0);
  auto less = [&](std::size_t i, std::size_t j) {
    return std::lexicographical_compare(p[i].data(), p[i].data() + 3, p[j].data(), p[j].data() + 3);
  };
  std::sort(order.begin(), order.end(),
            [&](std::size_t i, std::size_t j) { return less(i, j) || (!less(j, i) && i < j); });
  std::vector<char> keep(p.size(), 1);
  std::size_t dropped = 0;
  for (std::size_t k = 1; k < order.size(); ++k)
    if (p[order[k]] == p[order[k - 1]]) {
      keep[order[k]] = 0;
      ++dropped;
    }
  Compact(keep, cloud);
  return dropped;
}

// One pass of PCL's statistical outlier removal, restricted by spacing_ratio (see CleanOptions);
// the number of points it dropped.
std::size_t DropOutliersOnce(int neighbours, double std_ratio, double spacing_ratio,
                             PointCloud& cloud) {
  const std::size_t n = cloud.points_m.size();
  if (n <= static_cast<std::size_t>(neighbours)) return 0;
  // Recentred coordinates fit in float without loss that matters for neighbour statistics.
  auto points = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  points->resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d& p = cloud.points_m[i];
    (*points)[i] = pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                 static_cast<float>(p.z()));
  }
  pcl::StatisticalOutlierRemoval<pcl::PointXYZ> filter(/*extract_removed_indices=*/true);
  filter.setInputCloud(points);
  filter.setMeanK(neighbours);
  filter.setStddevMulThresh(std_ratio);
  pcl::Indices inliers;
  {
    QuietPcl quiet;
    filter.filter(inliers);
  }
  std::vector<char> keep(n, 0);
  for (auto i : inliers) keep[static_cast<std::size_t>(i)] = 1;
  const pcl::IndicesConstPtr flagged = filter.getRemovedIndices();
  if (spacing_ratio > 0 && !flagged->empty()) {
    // The mean distance to the neighbours, as the filter measures it, of every point: a flagged
    // point stays unless it is also spacing_ratio times the median of it away from the others.
    pcl::search::KdTree<pcl::PointXYZ> tree;
    tree.setInputCloud(points);
    pcl::Indices found(static_cast<std::size_t>(neighbours) + 1);
    std::vector<float> squared(found.size());
    std::vector<double> mean(n);
    for (std::size_t i = 0; i < n; ++i) {
      const int k = tree.nearestKSearch((*points)[i], neighbours + 1, found, squared);
      double sum = 0;
      for (int j = 1; j < k; ++j) sum += std::sqrt(static_cast<double>(squared[j]));  // j 0: itself
      mean[i] = k > 1 ? sum / (k - 1) : 0;
    }
    std::vector<double> sorted = mean;
    std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.end());
    const double limit = spacing_ratio * sorted[n / 2];
    for (auto i : *flagged)
      if (mean[static_cast<std::size_t>(i)] <= limit) keep[static_cast<std::size_t>(i)] = 1;
  }
  Compact(keep, cloud);
  return n - cloud.points_m.size();
}

// Repeats the pass until one drops nothing (or `passes` are done): the first pass's statistics
// are inflated by the outliers themselves, so far ones can hide nearer ones.
std::size_t DropOutliers(const CleanOptions& o, PointCloud& cloud) {
  std::size_t dropped = 0;
  for (int pass = 0; pass < o.outlier_passes; ++pass) {
    const std::size_t now =
        DropOutliersOnce(o.outlier_neighbours, o.outlier_std_ratio, o.outlier_spacing_ratio, cloud);
    dropped += now;
    if (now == 0) break;
  }
  return dropped;
}

std::size_t DownsampleVoxels(double voxel_m, PointCloud& cloud) {
  struct Cell {
    std::size_t index;
    double distance2;
  };
  struct KeyHash {
    std::size_t operator()(const std::array<std::int64_t, 3>& k) const {
      const auto u = [](std::int64_t v) { return static_cast<std::uint64_t>(v); };
      return std::hash<std::uint64_t>()(u(k[0]) * 73856093u ^ u(k[1]) * 19349663u ^
                                        u(k[2]) * 83492791u);
    }
  };
  std::unordered_map<std::array<std::int64_t, 3>, Cell, KeyHash> cells;
  for (std::size_t i = 0; i < cloud.points_m.size(); ++i) {
    const Eigen::Vector3d cell = (cloud.points_m[i] / voxel_m).array().floor();
    const double distance2 =
        (cloud.points_m[i] - (cell.array() + 0.5).matrix() * voxel_m).squaredNorm();
    const std::array<std::int64_t, 3> key = {static_cast<std::int64_t>(cell.x()),
                                             static_cast<std::int64_t>(cell.y()),
                                             static_cast<std::int64_t>(cell.z())};
    auto [it, added] = cells.try_emplace(key, Cell{i, distance2});
    if (!added && distance2 < it->second.distance2) it->second = Cell{i, distance2};
  }
  std::vector<char> keep(cloud.points_m.size(), 0);
  for (const auto& entry : cells) keep[entry.second.index] = 1;
  const std::size_t before = cloud.points_m.size();
  Compact(keep, cloud);
  return before - cloud.points_m.size();
}

}  // namespace

PointCloud ReadPointCloud(const std::string& path) {
  namespace fs = std::filesystem;
  const std::string ext = Lowercase(fs::path(path).extension().string());
  const bool pcd = ext == ".pcd", ply = ext == ".ply", pts = ext == ".pts";
  if (!pcd && !ply && !pts && ext != ".xyz" && ext != ".txt" && ext != ".csv")
    throw InputError(path + ": unknown point cloud format '" + ext +
                     "'; expected .pcd, .ply, .xyz, .txt, .csv or .pts");
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path + ": no such file");
  if (!fs::is_regular_file(path, ec)) throw InputError(path + ": not a regular file");
  if (fs::file_size(path, ec) == 0) throw InputError(path + ": the file is empty");

  PointCloud cloud = pcd || ply ? ReadPclPoints(path, pcd) : ReadTextPoints(path, pts);
  if (cloud.points_m.empty()) throw InputError(path + ": the file contains no points");
  // Beyond any georeferenced coordinate; squares of such numbers overflow to infinity.
  for (std::size_t i = 0; i < cloud.points_m.size(); ++i) {
    const Eigen::Vector3d& p = cloud.points_m[i];
    if (!p.allFinite() || p.cwiseAbs().maxCoeff() <= kMaxCoordinate_m) continue;
    std::ostringstream msg;
    msg << path << ":";
    if (cloud.source_lines.empty())
      msg << " point " << i + 1;
    else
      msg << cloud.source_lines[i];
    msg << ": coordinates (" << p.transpose() << ") out of range: beyond +-" << kMaxCoordinate_m
        << " m, not metres?";
    throw InputError(msg.str());
  }
  Recentre(cloud);
  return cloud;
}

void WritePolyhedronPly(const Polyhedron& poly, const Eigen::Vector3d& offset_m,
                        const std::string& path) {
  std::ostringstream out;
  out << "ply\nformat ascii 1.0\ncomment Talus convex hull, metres\n"
      << "element vertex " << poly.vertices_m.size() << "\n"
      << "property double x\nproperty double y\nproperty double z\n"
      << "element face " << poly.triangles.size() << "\n"
      << "property list uchar int vertex_indices\nend_header\n";
  out.precision(15);
  for (const auto& v : poly.vertices_m) {
    const Eigen::Vector3d p = v + offset_m;
    out << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  for (const auto& t : poly.triangles) out << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
  try {
    WriteFileAtomically(path, out.str());  // complete or absent
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot write the file (" + e.what() + ")");
  }
}

bool CleanOptions::IsValid(std::string* why) const {
  std::ostringstream msg;
  if (outlier_neighbours < 0 || outlier_neighbours > 1000)
    msg << "outlier_neighbours = " << outlier_neighbours
        << " violates 0 <= outlier_neighbours <= 1000";
  else if (!(outlier_std_ratio > 0) || !std::isfinite(outlier_std_ratio))
    msg << "outlier_std_ratio = " << outlier_std_ratio << " violates 0 < outlier_std_ratio < inf";
  else if (!(outlier_spacing_ratio >= 0) || !std::isfinite(outlier_spacing_ratio))
    msg << "outlier_spacing_ratio = " << outlier_spacing_ratio
        << " violates 0 <= outlier_spacing_ratio < inf";
  else if (outlier_passes < 1 || outlier_passes > 100)
    msg << "outlier_passes = " << outlier_passes << " violates 1 <= outlier_passes <= 100";
  else if (!(voxel_m == 0 || voxel_m >= kMinVoxel_m) || !std::isfinite(voxel_m))
    msg << "voxel_m = " << voxel_m << " violates voxel_m = 0 (off) or " << kMinVoxel_m
        << " <= voxel_m < inf m";
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

CleanReport CleanPointCloud(const CleanOptions& options, PointCloud* cloud) {
  CleanReport report;
  report.points_in = cloud->points_m.size();
  report.non_finite = DropNonFinite(options.drop_non_finite, *cloud);
  if (options.drop_duplicates) report.duplicates = DropDuplicates(*cloud);
  if (options.outlier_neighbours > 0) report.outliers = DropOutliers(options, *cloud);
  if (options.voxel_m > 0) report.downsampled = DownsampleVoxels(options.voxel_m, *cloud);
  report.points_out = cloud->points_m.size();
  return report;
}

}  // namespace talus::pointclouds
