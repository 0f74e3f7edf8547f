#include "io/geopackage.hpp"

#include <gdal_priv.h>
#include <ogr_feature.h>
#include <ogr_geometry.h>
#include <ogrsf_frmts.h>

#include <algorithm>
#include <array>
#include <memory>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "common/atomic_file.hpp"
#include "common/csv_table.hpp"
#include "common/error.hpp"
#include "common/format.hpp"
#include "io/layer_styles.hpp"
#include "io/map_classes.hpp"
#include "io/raster.hpp"
#include "io/trajectory_file.hpp"

namespace talus::io {
namespace {

constexpr int kFeaturesPerTransaction = 20000;

// Colours of the scene's layers: releases purple, trees green; evaluation lines and barriers as
// the quick-look draws them, black over a white halo.
constexpr std::array<unsigned char, 3> kReleaseRgb = {152, 78, 163};
constexpr std::array<unsigned char, 3> kTreeRgb = {35, 139, 69};
std::string MapLineQml() { return SingleSymbolQml({SymbolKind::kLine, {0, 0, 0}, 1, 0.6, true}); }

// The field type of a rocks.csv, evaluation_lines.csv or barriers.csv column: counts and indices
// as integers, names as text, the rest (coordinates, distances, speeds, energies, masses) as reals.
OGRFieldType FieldType(const std::string& column) {
  static const char* const integers[] = {"rock", "release", "seed", "crossings"};
  static const char* const texts[] = {"run",  "end",     "block", "end_ground", "end_barrier",
                                      "line", "barrier", "type",  "outcome"};
  for (const char* name : integers)
    if (column == name) return OFTInteger64;
  for (const char* name : texts)
    if (column == name) return OFTString;
  return OFTReal;
}

// GDAL's settings for writing the GeoPackage, while alive (this thread only):
// - its clock, fixed for the GeoPackage's last_change;
// - the spatial indexes built by SQLite as the features go in, not in a background thread from an
//   in-memory R-tree that grows with the features (GDAL >= 3.6). That kept about 3 MB more per
//   10^5 rocks, and took longer on the clock (5 s against 9 s for 10^5 rocks' end points);
// - SQLite's page cache at 1 MB.
class GpkgWriteSettings {
 public:
  GpkgWriteSettings() {
    CPLSetThreadLocalConfigOption("OGR_CURRENT_DATE", "2000-01-01T00:00:00.000Z");
    CPLSetThreadLocalConfigOption("OGR_GPKG_ALLOW_THREADED_RTREE", "NO");
    CPLSetThreadLocalConfigOption("OGR_SQLITE_CACHE", "1");
  }
  ~GpkgWriteSettings() {
    for (const char* key :
         {"OGR_CURRENT_DATE", "OGR_GPKG_ALLOW_THREADED_RTREE", "OGR_SQLITE_CACHE"})
      CPLSetThreadLocalConfigOption(key, nullptr);
  }
  GpkgWriteSettings(const GpkgWriteSettings&) = delete;
  GpkgWriteSettings& operator=(const GpkgWriteSettings&) = delete;
};

struct DatasetCloser {
  void operator()(GDALDataset* dataset) const { GDALClose(dataset); }
};

class Writer {
 public:
  Writer(const std::string& path, const std::string& temp_path, const std::string& crs_wkt)
      : path_(path) {
    RegisterGdal();
    GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GPKG");
    if (!driver) throw std::runtime_error("GDAL lacks the GPKG driver: cannot write " + path);
    dataset_.reset(driver->Create(temp_path.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    if (!dataset_) Fail("cannot create");
    srs_ = std::make_unique<OGRSpatialReference>();
    srs_->SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
    if (crs_wkt.empty()) {
      // Local coordinates in metres (the analytic plane): an engineering CRS, so that no GIS
      // takes them for longitude and latitude (GDAL's default for a layer without CRS).
      srs_->SetLocalCS("Talus local coordinates (m)");
      srs_->SetLinearUnits(SRS_UL_METER, 1.0);
    } else if (srs_->importFromWkt(crs_wkt.c_str()) != OGRERR_NONE) {
      Fail("cannot read the DEM's CRS");
    }
  }

  // A layer whose default style in QGIS is `qml`.
  OGRLayer* Layer(const char* name, OGRwkbGeometryType type, std::string qml) {
    OGRLayer* layer = dataset_->CreateLayer(name, srs_.get(), type, nullptr);
    if (!layer) Fail(std::string("cannot create the layer ") + name);
    styles_.push_back({name, layer->GetGeometryColumn(), std::move(qml)});
    return layer;
  }
  void Field(OGRLayer* layer, const std::string& name, OGRFieldType type) {
    OGRFieldDefn field(name.c_str(), type);
    if (layer->CreateField(&field) != OGRERR_NONE) Fail("cannot create the field " + name);
  }
  // Adds a feature inside a transaction that is committed every kFeaturesPerTransaction.
  void Add(OGRLayer* layer, OGRFeature& feature) {
    if (pending_ == 0 && dataset_->StartTransaction() != OGRERR_NONE) Fail("cannot write");
    if (layer->CreateFeature(&feature) != OGRERR_NONE) Fail("cannot write a feature");
    if (++pending_ == kFeaturesPerTransaction) Flush();
  }
  void Flush() {
    if (pending_ > 0 && dataset_->CommitTransaction() != OGRERR_NONE) Fail("cannot write");
    pending_ = 0;
  }
  void Close() {
    Flush();
    WriteStyles();
    CPLErrorReset();
    GDALClose(dataset_.release());  // GDAL 3.6: no status; a failure leaves its error
    if (CPLGetLastErrorType() >= CE_Failure) Fail("cannot write");
  }

 private:
  [[noreturn]] void Fail(const std::string& what) const {
    throw std::runtime_error(what + " " + path_ + ": " + CPLGetLastErrorMsg());
  }

  // Table `layer_styles` as QGIS reads it (an attributes table, listed in gpkg_contents): one
  // default style per layer, with a fixed update_time.
  void WriteStyles() {
    const char* const fid[] = {"FID=id", nullptr};
    OGRLayer* table =
        dataset_->CreateLayer("layer_styles", nullptr, wkbNone, const_cast<char**>(fid));
    if (!table) Fail("cannot create the table layer_styles");
    for (const char* name : {"f_table_catalog", "f_table_schema", "f_table_name",
                             "f_geometry_column", "styleName", "styleQML", "styleSLD"})
      Field(table, name, OFTString);
    OGRFieldDefn use_as_default("useAsDefault", OFTInteger);
    use_as_default.SetSubType(OFSTBoolean);
    if (table->CreateField(&use_as_default) != OGRERR_NONE)
      Fail("cannot create the field useAsDefault");
    for (const char* name : {"description", "owner", "ui"}) Field(table, name, OFTString);
    Field(table, "update_time", OFTDateTime);
    for (const Style& style : styles_) {
      OGRFeature feature(table->GetLayerDefn());
      feature.SetField("f_table_catalog", "");
      feature.SetField("f_table_schema", "");
      feature.SetField("f_table_name", style.layer.c_str());
      feature.SetField("f_geometry_column", style.geometry_column.c_str());
      feature.SetField("styleName", style.layer.c_str());
      feature.SetField("styleQML", style.qml.c_str());
      feature.SetField("styleSLD", "");
      feature.SetField("useAsDefault", 1);
      feature.SetField("description", "Talus default style");
      feature.SetField("owner", "");
      feature.SetField("update_time", 2000, 1, 1, 0, 0, 0.0f, 100);
      Add(table, feature);
    }
    Flush();
  }

  struct Style {
    std::string layer, geometry_column, qml;
  };

  std::string path_;
  std::vector<Style> styles_;
  std::unique_ptr<GDALDataset, DatasetCloser> dataset_;
  std::unique_ptr<OGRSpatialReference> srs_;
  int pending_ = 0;
};

// A layer of 3-D points at the columns x, y, z of `csv`, one per row, with every column as a
// field (an empty cell is null); read record by record.
void PointLayer(Writer& out, const char* name, const std::string& csv, const char* x_column,
                const char* y_column, const char* z_column, std::string qml) {
  CsvReader rows(csv);
  const std::vector<std::string>& columns = rows.header();
  const std::size_t x = rows.Column(x_column), y = rows.Column(y_column), z = rows.Column(z_column);
  OGRLayer* layer = out.Layer(name, wkbPoint25D, std::move(qml));
  for (const std::string& c : columns) out.Field(layer, c, FieldType(c));
  std::vector<std::string> fields;
  const auto number = [&](std::size_t c) {
    try {
      std::size_t used = 0;
      const double v = std::stod(fields[c], &used);
      if (used == fields[c].size()) return v;
    } catch (const std::exception&) {
    }
    throw InputError(csv + ":" + std::to_string(rows.line()) + ": column '" + columns[c] + "': '" +
                     fields[c] + "' is not a number");
  };
  while (rows.Next(&fields)) {
    OGRFeature feature(layer->GetLayerDefn());
    for (std::size_t c = 0; c < columns.size(); ++c) {
      if (fields[c].empty()) continue;  // null
      const OGRFieldType type = FieldType(columns[c]);
      if (type == OFTString)
        feature.SetField(static_cast<int>(c), fields[c].c_str());
      else if (type == OFTInteger64)
        feature.SetField(static_cast<int>(c), static_cast<GIntBig>(std::stoll(fields[c])));
      else
        feature.SetField(static_cast<int>(c), number(c));
    }
    OGRPoint point(number(x), number(y), number(z));
    feature.SetGeometry(&point);
    out.Add(layer, feature);
  }
  out.Flush();
}

// A 2-D ring or polyline as OGR geometry.
template <class Curve>
void SetVertices(Curve& curve, const std::vector<Eigen::Vector2d>& vertices) {
  curve.setNumPoints(static_cast<int>(vertices.size()));
  for (std::size_t k = 0; k < vertices.size(); ++k)
    curve.setPoint(static_cast<int>(k), vertices[k].x(), vertices[k].y());
}

// The scene's releases, evaluation lines and barriers (GeoPackageScene).
void SceneLayers(Writer& out, const GeoPackageScene& scene) {
  if (scene.release) {
    using Kind = ensemble::ReleaseGeometry::Kind;
    const ensemble::ReleaseSpec& r = *scene.release;
    for (const auto& [kind, name, type, symbol, opacity, width_mm] :
         {std::tuple{Kind::kPoint, "release_points", wkbPoint, SymbolKind::kMarker, 1.0, 2.6},
          std::tuple{Kind::kLine, "release_lines", wkbLineString, SymbolKind::kLine, 1.0, 0.8},
          std::tuple{Kind::kPolygon, "release_polygons", wkbPolygon, SymbolKind::kFill, 0.3,
                     0.5}}) {
      const bool runs = kind == Kind::kPoint && !r.runs.empty();
      const bool any = runs || std::any_of(r.releases.begin(), r.releases.end(),
                                           [k = kind](const auto& g) { return g.kind == k; });
      if (!any) continue;
      OGRLayer* layer =
          out.Layer(name, type, SingleSymbolQml({symbol, kReleaseRgb, opacity, width_mm}));
      out.Field(layer, "release", OFTInteger64);
      out.Field(layer, "name", OFTString);
      out.Field(layer, "rocks", OFTInteger64);
      const long count = r.release_count();
      for (long k = 0; k < count; ++k) {
        OGRFeature feature(layer->GetLayerDefn());
        feature.SetField(0, static_cast<GIntBig>(k));
        feature.SetField(1, r.ReleaseName(static_cast<int>(k)).c_str());
        feature.SetField(2, static_cast<GIntBig>(r.RocksOf(static_cast<int>(k))));
        if (runs) {
          const Eigen::Vector2d& p = r.runs[static_cast<std::size_t>(k)].xy_m;
          OGRPoint point(p.x(), p.y());
          feature.SetGeometry(&point);
        } else {
          const ensemble::ReleaseGeometry& g = r.releases[static_cast<std::size_t>(k)];
          if (g.kind != kind) continue;
          if (kind == Kind::kPoint) {
            OGRPoint point(g.rings[0][0].x(), g.rings[0][0].y());
            feature.SetGeometry(&point);
          } else if (kind == Kind::kLine) {
            OGRLineString line;
            SetVertices(line, g.rings[0]);
            feature.SetGeometry(&line);
          } else {
            OGRPolygon polygon;
            for (const std::vector<Eigen::Vector2d>& ring : g.rings) {
              OGRLinearRing closed;
              SetVertices(closed, ring);
              closed.closeRings();
              polygon.addRing(&closed);
            }
            feature.SetGeometry(&polygon);
          }
        }
        out.Add(layer, feature);
      }
      out.Flush();
    }
  }
  if (scene.evaluation_lines && !scene.evaluation_lines->empty()) {
    OGRLayer* layer = out.Layer("evaluation_lines", wkbLineString, MapLineQml());
    out.Field(layer, "name", OFTString);
    for (const ensemble::EvaluationLine& l : *scene.evaluation_lines) {
      OGRFeature feature(layer->GetLayerDefn());
      feature.SetField(0, l.name.c_str());
      OGRLineString line;
      SetVertices(line, l.vertices_m);
      feature.SetGeometry(&line);
      out.Add(layer, feature);
    }
    out.Flush();
  }
  if (scene.barriers && !scene.barriers->empty()) {
    OGRLayer* layer = out.Layer("barriers", wkbLineString, MapLineQml());
    out.Field(layer, "name", OFTString);
    out.Field(layer, "type", OFTString);
    out.Field(layer, "height_m", OFTReal);
    out.Field(layer, "capacity_kj", OFTReal);
    for (const Barrier& b : *scene.barriers) {
      OGRFeature feature(layer->GetLayerDefn());
      feature.SetField(0, b.name.c_str());
      feature.SetField(1, ToString(b.type));
      feature.SetField(2, b.height_m);
      feature.SetField(3, b.capacity_J / 1000);
      OGRLineString line;
      SetVertices(line, b.vertices_m);
      feature.SetGeometry(&line);
      out.Add(layer, feature);
    }
    out.Flush();
  }
}

// Layer `trees` (GeoPackageScene): the stems, with the hits of tree_impacts.csv summed per stem.
void TreeLayer(Writer& out, const Forest& forest, const std::string& tree_impacts_csv) {
  const std::size_t n = forest.stems().size();
  std::vector<long> rocks(n, 0), impacts(n, 0), broken(n, 0);
  std::vector<double> absorbed_J(n, 0.0);
  if (!tree_impacts_csv.empty()) {
    const CsvTable table = CsvTable::Read(tree_impacts_csv);
    table.Require({"tree", "impacts", "absorbed_J", "broken"});
    for (int row = 0; row < table.rows(); ++row) {
      const double tree = table.NonNegativeNumber(row, "tree");
      if (!(tree < static_cast<double>(n)) || tree != static_cast<double>(static_cast<long>(tree)))
        throw InputError(table.Where(row, "tree") + ": no tree " + TenDigits(tree) +
                         " in the forest of " + std::to_string(n) + " trees");
      const auto k = static_cast<std::size_t>(tree);
      ++rocks[k];
      impacts[k] += static_cast<long>(table.NonNegativeNumber(row, "impacts"));
      broken[k] += table.NonNegativeNumber(row, "broken") > 0;
      absorbed_J[k] += table.NonNegativeNumber(row, "absorbed_J");
    }
  }
  OGRLayer* layer =
      out.Layer("trees", wkbPoint25D, SingleSymbolQml({SymbolKind::kMarker, kTreeRgb, 1, 1.6}));
  out.Field(layer, "tree", OFTInteger64);
  out.Field(layer, "dbh_cm", OFTReal);
  out.Field(layer, "breaking_energy_kj", OFTReal);
  out.Field(layer, "rocks_hit", OFTInteger64);
  out.Field(layer, "impacts", OFTInteger64);
  out.Field(layer, "broken", OFTInteger64);
  out.Field(layer, "absorbed_kj", OFTReal);
  for (std::size_t k = 0; k < n; ++k) {
    const Stem& stem = forest.stems()[k];
    OGRFeature feature(layer->GetLayerDefn());
    feature.SetField(0, static_cast<GIntBig>(k));
    feature.SetField(1, 100 * stem.dbh_m);
    feature.SetField(2, forest.capacity_J(static_cast<int>(k)) / 1000);
    feature.SetField(3, static_cast<GIntBig>(rocks[k]));
    feature.SetField(4, static_cast<GIntBig>(impacts[k]));
    feature.SetField(5, static_cast<GIntBig>(broken[k]));
    feature.SetField(6, absorbed_J[k] / 1000);
    OGRPoint point(stem.position_m.x(), stem.position_m.y(), stem.ground_m);
    feature.SetGeometry(&point);
    out.Add(layer, feature);
  }
  out.Flush();
}

}  // namespace

void WriteRocksGeoPackage(const std::string& path, const std::string& rocks_csv,
                          const std::string& trajectories_h5, const std::string& crs_wkt,
                          const std::string& evaluation_lines_csv, const std::string& barriers_csv,
                          const GeoPackageScene& scene) {
  const GpkgWriteSettings settings;
  AtomicFile file(path);
  Writer out(path, file.temp_path(), crs_wkt);

  // Points coloured by energy, in the classes of the quick-look's energy map.
  PointLayer(out, "end_points", rocks_csv, "x_end", "y_end", "z_end",
             GraduatedMarkerQml("max_kinetic_energy_j", EnergyLegend()));
  if (!evaluation_lines_csv.empty())
    PointLayer(out, "evaluation_crossings", evaluation_lines_csv, "x_m", "y_m", "z_m",
               GraduatedMarkerQml("energy_J", EnergyLegend()));
  if (!barriers_csv.empty())
    PointLayer(out, "barrier_impacts", barriers_csv, "x_m", "y_m", "z_m",
               GraduatedMarkerQml("energy_J", EnergyLegend()));

  SceneLayers(out, scene);
  if (scene.forest && !scene.forest->empty()) TreeLayer(out, *scene.forest, scene.tree_impacts_csv);

  std::vector<std::string> fields;
  if (!trajectories_h5.empty()) {
    const TrajectoryReader trajectories(trajectories_h5);
    OGRLayer* lines =
        out.Layer("paths", wkbLineString25D,
                  SingleSymbolQml({SymbolKind::kLine, kPathRgb, kPathOpacity, 0.4, false}));
    out.Field(lines, "rock", OFTInteger64);
    out.Field(lines, "run", OFTString);
    out.Field(lines, "end", OFTString);
    CsvReader again(rocks_csv);  // a second pass: nothing per rock is kept in memory
    const std::size_t rock_column = again.Column("rock"), run_column = again.Column("run"),
                      end_column = again.Column("end");
    while (again.Next(&fields)) {
      const long rock = std::stol(fields[rock_column]);
      const StoredTrajectory t = trajectories.Read(rock);
      OGRLineString line;
      line.setNumPoints(static_cast<int>(t.samples.size()));
      for (std::size_t k = 0; k < t.samples.size(); ++k) {
        const Eigen::Vector3d& q = t.samples[k].position_m;
        line.setPoint(static_cast<int>(k), q.x(), q.y(), q.z());
      }
      OGRFeature feature(lines->GetLayerDefn());
      feature.SetField(0, static_cast<GIntBig>(rock));
      feature.SetField(1, fields[run_column].c_str());
      feature.SetField(2, fields[end_column].c_str());
      feature.SetGeometry(&line);
      out.Add(lines, feature);
    }
  }
  out.Close();
  file.Commit();
}

}  // namespace talus::io
