#include "io/vector.hpp"

#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <filesystem>
#include <functional>
#include <memory>

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

}  // namespace

namespace {

// Calls visit(feature, geometry in the target CRS, where) for every feature with a geometry.
template <class Visit>
void ForEachFeature(const std::string& path, const std::string& target_crs_wkt,
                    const std::string& what, const std::string& placed, Visit&& visit) {
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
  for (OGRLayer* layer : dataset->GetLayers()) {
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
                                                   const std::string& what) {
  std::vector<ReleaseGeometry> out;
  ForEachFeature(path, target_crs_wkt, what, "release",
                 [&](OGRFeature&, const OGRGeometry& geometry, const std::string& where) {
                   Collect(geometry, where, out);
                 });
  if (out.empty()) throw InputError(what + ": " + path + " has no point, line or polygon");
  return out;
}

std::vector<ensemble::EvaluationLine> ReadLineFeatures(const std::string& path,
                                                       const std::string& target_crs_wkt,
                                                       const std::string& name_field,
                                                       bool require_field, const std::string& what,
                                                       std::vector<std::string>* where_out) {
  std::vector<ensemble::EvaluationLine> out;
  std::function<void(const OGRGeometry&, const std::string&, const std::string&)> collect =
      [&](const OGRGeometry& geometry, const std::string& name, const std::string& where) {
        const OGRwkbGeometryType type = wkbFlatten(geometry.getGeometryType());
        if (type == wkbLineString) {
          const auto& line = *geometry.toLineString();
          ensemble::EvaluationLine& l = out.emplace_back();
          l.name = name;
          where_out->push_back(where);
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
  ForEachFeature(path, target_crs_wkt, what, "lines",
                 [&](OGRFeature& feature, const OGRGeometry& geometry, const std::string& where) {
                   const int field = feature.GetFieldIndex(name_field.c_str());
                   if (field < 0 && require_field)
                     throw InputError(where + ": no attribute '" + name_field + "'");
                   std::string name;
                   if (field >= 0 && feature.IsFieldSetAndNotNull(field))
                     name = feature.GetFieldAsString(field);
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
  ForEachFeature(path, target_crs_wkt, what, "observations",
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

}  // namespace talus::io
