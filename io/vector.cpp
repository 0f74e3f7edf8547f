#include "io/vector.hpp"

#include <cpl_error.h>
#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include "common/error.hpp"
#include "io/raster.hpp"

namespace talus::io {
namespace {

using ensemble::ReleaseGeometry;

std::vector<Eigen::Vector2d> Ring(const OGRSimpleCurve& curve) {
  std::vector<Eigen::Vector2d> ring;
  for (int k = 0; k < curve.getNumPoints(); ++k) ring.emplace_back(curve.getX(k), curve.getY(k));
  // Closed rings repeat their first point; the release sampler does not need that.
  if (ring.size() > 1 && ring.front() == ring.back()) ring.pop_back();
  return ring;
}

void Collect(const OGRGeometry& geometry, const std::string& where,
             std::vector<ReleaseGeometry>& out) {
  switch (wkbFlatten(geometry.getGeometryType())) {
    case wkbPoint: {
      const auto& p = *geometry.toPoint();
      out.push_back({ReleaseGeometry::Kind::kPoint, {{Eigen::Vector2d(p.getX(), p.getY())}}});
      return;
    }
    case wkbLineString: {
      // A line whose ends meet is still a line: keep both ends.
      const auto& line = *geometry.toLineString();
      std::vector<Eigen::Vector2d> ring;
      for (int k = 0; k < line.getNumPoints(); ++k) ring.emplace_back(line.getX(k), line.getY(k));
      out.push_back({ReleaseGeometry::Kind::kLine, {ring}});
      return;
    }
    case wkbPolygon: {
      const auto& polygon = *geometry.toPolygon();
      ReleaseGeometry g{ReleaseGeometry::Kind::kPolygon, {}};
      if (polygon.getExteriorRing()) g.rings.push_back(Ring(*polygon.getExteriorRing()));
      for (int k = 0; k < polygon.getNumInteriorRings(); ++k)
        g.rings.push_back(Ring(*polygon.getInteriorRing(k)));
      out.push_back(std::move(g));
      return;
    }
    case wkbMultiPoint:
    case wkbMultiLineString:
    case wkbMultiPolygon:
    case wkbGeometryCollection:
      for (const OGRGeometry* part : *geometry.toGeometryCollection()) Collect(*part, where, out);
      return;
    default:
      throw InputError(where + ": unsupported geometry type " + geometry.getGeometryName() +
                       " (points, lines and polygons are)");
  }
}

// The names of `feature`'s fields, "a, b, c" ("none").
std::string FieldNames(OGRFeature& feature) {
  std::string fields;
  for (int k = 0; k < feature.GetFieldCount(); ++k)
    fields += (k ? ", " : "") + std::string(feature.GetFieldDefnRef(k)->GetNameRef());
  return fields.empty() ? "none" : fields;
}

}  // namespace

namespace {

// The layers of `dataset` that `select` chooses (null: all of them).
std::vector<OGRLayer*> SelectLayers(GDALDataset& dataset, const std::string& path,
                                    const FeatureSelection* select) {
  std::vector<OGRLayer*> all;
  std::string names;
  for (OGRLayer* layer : dataset.GetLayers()) {
    all.push_back(layer);
    names += std::string(names.empty() ? "" : ", ") + "'" + layer->GetName() + "'";
  }
  if (!select) return all;
  OGRLayer* chosen = nullptr;
  if (select->layer.empty()) {
    if (all.size() > 1)
      throw InputError(select->layer_what + ": " + path + " has " + std::to_string(all.size()) +
                       " layers (" + names + "): choose one with layer = \"...\"");
    if (!all.empty()) chosen = all.front();
  } else {
    for (OGRLayer* layer : all)
      if (select->layer == layer->GetName()) chosen = layer;
    if (!chosen)
      throw InputError(select->layer_what + ": " + path + " has no layer '" + select->layer +
                       "' (its layers: " + names + ")");
  }
  if (!chosen) return {};
  // GDAL reports a bad clause through its error handler as well: keep it off stderr. Some drivers
  // (GeoPackage) check the clause only when reading: read one feature to see.
  CPLPushErrorHandler(CPLQuietErrorHandler);
  CPLErrorReset();
  OGRErr error =
      chosen->SetAttributeFilter(select->where.empty() ? nullptr : select->where.c_str());
  if (error == OGRERR_NONE && !select->where.empty()) {
    chosen->ResetReading();
    OGRFeature::DestroyFeature(chosen->GetNextFeature());
    if (CPLGetLastErrorType() >= CE_Failure) error = OGRERR_FAILURE;
    chosen->ResetReading();
  }
  const std::string message = CPLGetLastErrorMsg();
  CPLPopErrorHandler();
  if (error != OGRERR_NONE)
    throw InputError(select->where_what + ": '" + select->where + "' is not a valid filter of " +
                     path + " layer '" + chosen->GetName() + "'" +
                     (message.empty() ? "" : ": " + message));
  return {chosen};
}

// Calls visit(feature, geometry in the target CRS, where) for every feature with a geometry of
// the layers `select` chooses (null: every layer).
template <class Visit>
void ForEachFeature(const std::string& path, const std::string& target_crs_wkt,
                    const std::string& what, const std::string& placed,
                    const FeatureSelection* select, Visit&& visit) {
  RegisterGdal();
  if (!std::filesystem::exists(path)) throw InputError(what + ": file not found: " + path);
  std::unique_ptr<GDALDataset> dataset(GDALDataset::Open(
      path.c_str(), GDAL_OF_VECTOR | GDAL_OF_READONLY, nullptr, nullptr, nullptr));
  if (!dataset) throw InputError(what + ": GDAL/OGR cannot read " + path + " as a vector file");
  OGRSpatialReference target;
  if (!target_crs_wkt.empty()) {
    target.importFromWkt(target_crs_wkt.c_str());
    target.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  }
  for (OGRLayer* layer : SelectLayers(*dataset, path, select)) {
    std::unique_ptr<OGRCoordinateTransformation> transform;
    const OGRSpatialReference* source = layer->GetSpatialRef();
    if (source && target_crs_wkt.empty()) {
      // GDAL reports WGS 84 for every GeoJSON file without a "crs" member (RFC 7946); a scene
      // without a CRS (the plane, a DEM without one) takes such coordinates as they are.
      const char* code = source->GetAuthorityCode(nullptr);
      const bool geojson_default =
          std::string(dataset->GetDriver()->GetDescription()) == "GeoJSON" && code &&
          std::string(code) == "4326";
      if (!geojson_default)
        throw InputError(what + ": " + path + " has a CRS but the DEM has none, so the " + placed +
                         " cannot be placed");
    } else if (source && !source->IsSame(&target)) {
      OGRSpatialReference s(*source);
      s.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
      transform.reset(OGRCreateCoordinateTransformation(&s, &target));
      if (!transform)
        throw InputError(what + ": no transformation from the CRS of " + path + " to the DEM's");
    }
    for (auto& feature : *layer) {
      const OGRGeometry* geometry = feature->GetGeometryRef();
      if (!geometry) continue;
      std::unique_ptr<OGRGeometry> copy(geometry->clone());
      if (transform && copy->transform(transform.get()) != OGRERR_NONE)
        throw InputError(what + ": cannot transform feature " + std::to_string(feature->GetFID()) +
                         " of " + path + " to the DEM's CRS");
      visit(*feature, *copy,
            what + " (" + path + ", feature " + std::to_string(feature->GetFID()) + ")");
    }
  }
}

}  // namespace

std::vector<ReleaseGeometry> ReadReleaseGeometries(const std::string& path,
                                                   const std::string& target_crs_wkt,
                                                   const std::string& what,
                                                   const FeatureSelection& select) {
  FeatureSelection named = select;
  if (named.layer_what.empty()) named.layer_what = what;
  if (named.where_what.empty()) named.where_what = what;
  std::vector<ReleaseGeometry> out;
  ForEachFeature(path, target_crs_wkt, what, "release", &named,
                 [&](OGRFeature&, const OGRGeometry& geometry, const std::string& where) {
                   Collect(geometry, where, out);
                 });
  if (out.empty())
    throw InputError(what + ": " + path + " has no point, line or polygon" +
                     (select.where.empty() ? "" : " where " + select.where));
  return out;
}

std::vector<GroundPolygon> ReadGroundPolygons(const std::string& path,
                                              const std::string& target_crs_wkt,
                                              const std::string& field, const std::string& what) {
  std::vector<GroundPolygon> out;
  ForEachFeature(path, target_crs_wkt, what, "ground polygons", nullptr,
                 [&](OGRFeature& feature, const OGRGeometry& geometry, const std::string& where) {
                   const int index = feature.GetFieldIndex(field.c_str());
                   if (index < 0)
                     throw InputError(where + ": no field '" + field +
                                      "' (the fields are: " + FieldNames(feature) + ")");
                   if (!feature.IsFieldSetAndNotNull(index))
                     throw InputError(where + ": field '" + field + "' is empty");
                   GroundPolygon polygon;
                   polygon.where = where;
                   const OGRFieldType type = feature.GetFieldDefnRef(index)->GetType();
                   if (type == OFTInteger || type == OFTInteger64 || type == OFTReal) {
                     const double v = feature.GetFieldAsDouble(index);
                     if (v != std::floor(v) || std::abs(v) > 1e9)
                       throw InputError(where + ": field '" + field + "' is " +
                                        feature.GetFieldAsString(index) +
                                        ", not an integer category code");
                     polygon.value = std::to_string(static_cast<long>(v));
                     polygon.numeric = true;
                   } else {
                     polygon.value = feature.GetFieldAsString(index);
                     if (polygon.value.empty())
                       throw InputError(where + ": field '" + field + "' is empty");
                   }
                   std::vector<ReleaseGeometry> parts;
                   Collect(geometry, where, parts);
                   for (ReleaseGeometry& part : parts) {
                     if (part.kind != ReleaseGeometry::Kind::kPolygon)
                       throw InputError(where + ": a ground polygon must be a polygon, not a " +
                                        std::string(geometry.getGeometryName()));
                     polygon.rings = std::move(part.rings);
                     out.push_back(polygon);
                   }
                 });
  if (out.empty()) throw InputError(what + ": " + path + " has no polygon");
  return out;
}

std::vector<ensemble::EvaluationLine> ReadLineFeatures(
    const std::string& path, const std::string& target_crs_wkt, const std::string& name_field,
    bool require_field, const std::string& what, std::vector<std::string>* where_out,
    const std::vector<std::string>& fields, std::vector<std::vector<FeatureValue>>* values) {
  std::vector<ensemble::EvaluationLine> out;
  std::vector<FeatureValue> feature_values;  // of the feature being collected
  std::function<void(const OGRGeometry&, const std::string&, const std::string&)> collect =
      [&](const OGRGeometry& geometry, const std::string& name, const std::string& where) {
        const OGRwkbGeometryType type = wkbFlatten(geometry.getGeometryType());
        if (type == wkbLineString) {
          const auto& line = *geometry.toLineString();
          ensemble::EvaluationLine& l = out.emplace_back();
          l.name = name;
          where_out->push_back(where);
          if (values) values->push_back(feature_values);
          for (int k = 0; k < line.getNumPoints(); ++k)
            l.vertices_m.emplace_back(line.getX(k), line.getY(k));
        } else if (type == wkbMultiLineString) {
          for (const OGRGeometry* part : *geometry.toGeometryCollection())
            collect(*part, name, where);
        } else {
          throw InputError(where + ": an evaluation line must be a line or multi-line, not a " +
                           std::string(geometry.getGeometryName()));
        }
      };
  ForEachFeature(path, target_crs_wkt, what, "lines", nullptr,
                 [&](OGRFeature& feature, const OGRGeometry& geometry, const std::string& where) {
                   const int field = feature.GetFieldIndex(name_field.c_str());
                   if (field < 0 && require_field)
                     throw InputError(where + ": no attribute '" + name_field + "'");
                   std::string name;
                   if (field >= 0 && feature.IsFieldSetAndNotNull(field))
                     name = feature.GetFieldAsString(field);
                   feature_values.assign(fields.size(), FeatureValue{});
                   for (std::size_t k = 0; k < fields.size(); ++k) {
                     FeatureValue& v = feature_values[k];
                     const int index = feature.GetFieldIndex(fields[k].c_str());
                     if (index < 0) {
                       v.fields = FieldNames(feature);
                       continue;
                     }
                     if (!feature.IsFieldSetAndNotNull(index)) {
                       v.kind = FeatureValue::Kind::kNull;
                       continue;
                     }
                     v.text = feature.GetFieldAsString(index);
                     const OGRFieldType t = feature.GetFieldDefnRef(index)->GetType();
                     v.kind = t == OFTInteger || t == OFTInteger64 || t == OFTReal
                                  ? FeatureValue::Kind::kNumber
                                  : FeatureValue::Kind::kText;
                     if (v.kind == FeatureValue::Kind::kNumber)
                       v.number = feature.GetFieldAsDouble(index);
                   }
                   collect(geometry, name, where);
                 });
  if (out.empty()) throw InputError(what + ": " + path + " has no line");
  return out;
}

std::vector<fieldobs::DepositObservation> ReadDepositPoints(const std::string& path,
                                                            const std::string& target_crs_wkt,
                                                            const std::string& run_field,
                                                            const std::string& what) {
  std::vector<fieldobs::DepositObservation> out;
  ForEachFeature(path, target_crs_wkt, what, "observations", nullptr,
                 [&](OGRFeature& feature, const OGRGeometry& geometry, const std::string& where) {
                   if (wkbFlatten(geometry.getGeometryType()) != wkbPoint)
                     throw InputError(where + ": a rest position must be a point, not a " +
                                      std::string(geometry.getGeometryName()));
                   const auto& p = *geometry.toPoint();
                   fieldobs::DepositObservation d;
                   d.xy_m = Eigen::Vector2d(p.getX(), p.getY());
                   if (!d.xy_m.allFinite()) throw InputError(where + ": non-finite coordinates");
                   const int run = feature.GetFieldIndex(run_field.c_str());
                   if (run >= 0) {
                     d.run = feature.GetFieldAsString(run);
                     if (d.run.empty()) throw InputError(where + ": empty " + run_field);
                   }
                   const int radius = feature.GetFieldIndex("radius_m");
                   if (radius >= 0 && feature.IsFieldSetAndNotNull(radius)) {
                     d.radius_m = feature.GetFieldAsDouble(radius);
                     if (!(*d.radius_m >= 0)) throw InputError(where + ": radius_m must be >= 0");
                   }
                   d.where = path + " feature " + std::to_string(feature.GetFID());
                   out.push_back(d);
                 });
  if (out.empty()) throw InputError(what + ": " + path + " has no point");
  return out;
}

namespace {

// The text of `feature`'s attribute `field`: absent when its layer has no such field, "" when null.
std::optional<std::string> OptionalText(OGRFeature& feature, const std::string& field) {
  const int index = feature.GetFieldIndex(field.c_str());
  if (index < 0) return std::nullopt;
  return feature.IsFieldSetAndNotNull(index) ? feature.GetFieldAsString(index) : "";
}

}  // namespace

std::vector<TreePoint> ReadTreePoints(const std::string& path, const std::string& target_crs_wkt,
                                      const std::string& dbh_field,
                                      const std::string& species_field, bool require_species,
                                      const std::string& what) {
  std::vector<TreePoint> out;
  ForEachFeature(path, target_crs_wkt, what, "trees", nullptr,
                 [&](OGRFeature& feature, const OGRGeometry& geometry, const std::string& where) {
                   if (wkbFlatten(geometry.getGeometryType()) != wkbPoint)
                     throw InputError(where + ": a tree must be a point, not a " +
                                      std::string(geometry.getGeometryName()));
                   const auto& p = *geometry.toPoint();
                   TreePoint t;
                   t.xy_m = Eigen::Vector2d(p.getX(), p.getY());
                   if (!t.xy_m.allFinite()) throw InputError(where + ": non-finite coordinates");
                   const int field = feature.GetFieldIndex(dbh_field.c_str());
                   if (field < 0)
                     throw InputError(where + ": no field '" + dbh_field +
                                      "' (the stem diameter at breast height, cm)");
                   if (!feature.IsFieldSetAndNotNull(field))
                     throw InputError(where + ": " + dbh_field + " is empty");
                   t.dbh_cm = feature.GetFieldAsDouble(field);
                   t.species = OptionalText(feature, species_field);
                   if (!t.species && require_species)
                     throw InputError(where + ": no field '" + species_field +
                                      "' (species_field: the tree's species; the fields are: " +
                                      FieldNames(feature) + ")");
                   t.where = where;
                   out.push_back(t);
                 });
  if (out.empty()) throw InputError(what + ": " + path + " has no point");
  return out;
}

std::vector<StandPolygon> ReadStandPolygons(const std::string& path,
                                            const std::string& target_crs_wkt,
                                            const std::string& what) {
  std::vector<StandPolygon> out;
  ForEachFeature(path, target_crs_wkt, what, "stands", nullptr,
                 [&](OGRFeature& feature, const OGRGeometry& geometry, const std::string& where) {
                   StandPolygon stand;
                   stand.where = where;
                   const auto number = [&](const char* field,
                                           bool required) -> std::optional<double> {
                     const int index = feature.GetFieldIndex(field);
                     if (index < 0 || !feature.IsFieldSetAndNotNull(index)) {
                       if (required)
                         throw InputError(where + ": no value in field '" + field + "'");
                       return std::nullopt;
                     }
                     const OGRFieldType type = feature.GetFieldDefnRef(index)->GetType();
                     if (type != OFTInteger && type != OFTInteger64 && type != OFTReal)
                       throw InputError(where + ": field '" + field + "' is not a number");
                     return feature.GetFieldAsDouble(index);
                   };
                   stand.stems_per_ha = *number("stems_per_ha", true);
                   stand.dbh_cm = *number("dbh_cm", true);
                   stand.dbh_sd_cm = number("dbh_sd_cm", false).value_or(0.0);
                   stand.species = OptionalText(feature, "species");
                   std::vector<ReleaseGeometry> parts;
                   Collect(geometry, where, parts);
                   for (ReleaseGeometry& part : parts) {
                     if (part.kind != ReleaseGeometry::Kind::kPolygon)
                       throw InputError(where + ": a stand must be a polygon, not a " +
                                        std::string(geometry.getGeometryName()));
                     stand.rings = std::move(part.rings);
                     out.push_back(stand);
                   }
                 });
  if (out.empty()) throw InputError(what + ": " + path + " has no polygon");
  return out;
}

}  // namespace talus::io
