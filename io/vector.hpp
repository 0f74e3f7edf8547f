#pragma once
// Release geometries from vector files GDAL/OGR reads (GeoJSON, GeoPackage, Shapefile, ...).

#include <string>
#include <vector>

#include "ensemble/release.hpp"

namespace talus::io {

// Every point, line and polygon of every layer (multi-geometries are split), in the CRS
// `target_crs_wkt` when both it and the file have a CRS, else as stored. `what` names the scene
// key in errors. Throws InputError (missing file, no features, unsupported geometry, a CRS the
// DEM lacks).
std::vector<ensemble::ReleaseGeometry> ReadReleaseGeometries(const std::string& path,
                                                             const std::string& target_crs_wkt,
                                                             const std::string& what);

}  // namespace talus::io
