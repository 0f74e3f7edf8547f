#include "io/vector.hpp"

#include <gdal_priv.h>
#include <ogrsf_frmts.h>

#include <filesystem>
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

std::vector<ReleaseGeometry> ReadReleaseGeometries(const std::string& path,
                                                   const std::string& target_crs_wkt,
                                                   const std::string& what) {
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
  std::vector<ReleaseGeometry> out;
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
        throw InputError(what + ": " + path +
                         " has a CRS but the DEM has none, so the release cannot be placed");
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
      Collect(*copy, what + " (" + path + ", feature " + std::to_string(feature->GetFID()) + ")",
              out);
    }
  }
  if (out.empty()) throw InputError(what + ": " + path + " has no point, line or polygon");
  return out;
}

}  // namespace talus::io
