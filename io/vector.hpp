#pragma once
// Release geometries from vector files GDAL/OGR reads (GeoJSON, GeoPackage, Shapefile, ...).

#include <optional>
#include <string>
#include <vector>

#include "ensemble/evaluation_lines.hpp"
#include "ensemble/release.hpp"
#include "fieldobs/observations.hpp"

namespace talus::io {

// Which features of a vector file: those of `layer` (empty: the file's only layer; a file of
// several layers is then an error listing them) that pass the OGR attribute filter `where`
// (OGRLayer::SetAttributeFilter, an SQL WHERE clause such as "zone = 'A' AND active = 1"; empty:
// all). `layer_what` and `where_what` name the scene keys in errors.
struct FeatureSelection {
  std::string layer, layer_what;
  std::string where, where_what;
};

// Every point, line and polygon of the selected features (multi-geometries are split), in the CRS
// `target_crs_wkt` when both it and the file have a CRS, else as stored. `what` names the scene
// key in errors. Throws InputError (missing file, no features, unsupported geometry, a CRS the
// DEM lacks, an unknown layer, several layers and none chosen, a bad where clause).
std::vector<ensemble::ReleaseGeometry> ReadReleaseGeometries(const std::string& path,
                                                             const std::string& target_crs_wkt,
                                                             const std::string& what,
                                                             const FeatureSelection& select = {});

// One polygon of a ground map: its rings (the outer ring first, then holes; not repeating the first
// point) and the value of the category field as text (numbers as integers: "6").
struct GroundPolygon {
  std::vector<std::vector<Eigen::Vector2d>> rings;
  std::string value;
  bool numeric = false;  // the field is a number (a category code), not text
  std::string where;     // "<what> (<file>, feature <fid>)", for errors
};

// Every polygon of every layer of a vector file (multi-polygons split), in feature order, in the
// CRS `target_crs_wkt` as for releases, with the value of the field `field`. Throws InputError
// naming `what`, the file and the feature: missing file, no polygon, a point or line feature, no
// field of that name (listing the fields there are), an empty value or a number that is not an
// integer.
std::vector<GroundPolygon> ReadGroundPolygons(const std::string& path,
                                              const std::string& target_crs_wkt,
                                              const std::string& field, const std::string& what);

// The lines of a vector file (evaluation lines): every line feature, multi-lines split into their
// parts, in the DEM's CRS as for ReadReleaseGeometries. Each line is named by its feature's
// `name_field` attribute; a file without that field gives unnamed lines (empty names), unless
// `require_field`. Other geometries are errors. Throws InputError naming `what`, the file and the
// feature. *where gets, per line, "<what> (<path>, feature <fid>)" for the caller's checks.
// With `fields`, *values gets per line the values of those attributes of its feature, in order
// (FeatureValue: absent when the layer has no such field or the feature's is null).
struct FeatureValue {
  enum class Kind { kNoField, kNull, kNumber, kText };
  Kind kind = Kind::kNoField;
  double number = 0;   // kNumber
  std::string text;    // kNumber and kText: the value as GDAL prints it
  std::string fields;  // kNoField: the layer's fields, "a, b, c" ("none")
};
std::vector<ensemble::EvaluationLine> ReadLineFeatures(
    const std::string& path, const std::string& target_crs_wkt, const std::string& name_field,
    bool require_field, const std::string& what, std::vector<std::string>* where,
    const std::vector<std::string>& fields = {},
    std::vector<std::vector<FeatureValue>>* values = nullptr);

// Surveyed rest positions from the point features of a vector file, in the DEM's CRS: reprojected
// when the file and the DEM both have a CRS; an error when the file has one and the DEM none (a
// GeoJSON without a "crs" member is taken as local coordinates then, as for releases). Each
// feature's run is its `run_field` attribute (absent field: the whole scene), its uncertainty the
// optional `radius_m` attribute. Throws InputError naming `what`, the file and the feature.
std::vector<fieldobs::DepositObservation> ReadDepositPoints(const std::string& path,
                                                            const std::string& target_crs_wkt,
                                                            const std::string& run_field,
                                                            const std::string& what);

// One tree of a point vector file (ReadTreePoints).
struct TreePoint {
  Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();  // in the DEM's CRS
  double dbh_cm = 0;                               // as stored, unchecked
  // The species attribute as text: absent when the layer has no such field, "" when null.
  std::optional<std::string> species;
  std::string where;  // "<what> (<file>, feature <fid>)"
};

// The trees of a vector file of points (a [forest] trees file other than CSV): every point
// feature of every layer, reprojected to the DEM's CRS as for ReadReleaseGeometries (an error when
// the file has a CRS and the DEM none), each with the number in its `dbh_field` attribute and the
// text of its `species_field` attribute where the layer has one. Throws InputError naming `what`,
// the file and the feature: not a point, no DBH field (or, with `require_species`, no species
// field), an empty DBH, no point at all.
std::vector<TreePoint> ReadTreePoints(const std::string& path, const std::string& target_crs_wkt,
                                      const std::string& dbh_field,
                                      const std::string& species_field, bool require_species,
                                      const std::string& what);

// One forest stand of a polygon vector file (ReadStandPolygons).
struct StandPolygon {
  std::vector<std::vector<Eigen::Vector2d>> rings;     // outer ring, then holes; in the DEM's CRS
  double stems_per_ha = 0, dbh_cm = 0, dbh_sd_cm = 0;  // as stored, unchecked
  std::optional<std::string> species;  // as TreePoint's, from the attribute `species`
  std::string where;                   // "<what> (<file>, feature <fid>)"
};

// The stands of a vector file of polygons ([forest] stands_file): every polygon feature of every
// layer (multi-polygons split), reprojected to the DEM's CRS as for ReadReleaseGeometries, with
// the numeric attributes stems_per_ha and dbh_cm, the optional dbh_sd_cm (0 when absent) and the
// optional text attribute species. Throws InputError naming `what`, the file and the feature.
std::vector<StandPolygon> ReadStandPolygons(const std::string& path,
                                            const std::string& target_crs_wkt,
                                            const std::string& what);

}  // namespace talus::io
