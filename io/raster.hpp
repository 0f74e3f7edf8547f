#pragma once
// GDAL rasters: reading a DEM or a code raster into the solver's grid convention, and writing
// GeoTIFFs on a grid with its CRS.

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "solver/option_table.hpp"
#include "solver/terrain.hpp"

namespace talus::io {

// A single-band raster in the solver's convention: node (i, j) at the centre of cell (i, j), i
// along x, j along y (GDAL's rows are flipped), values row j after row j - 1, NaN where nodata
// (the declared nodata value, or NaN); infinite values are kept as they are.
struct Raster {
  GridGeometry grid;
  std::vector<double> values;
  std::string crs_wkt;  // empty when the file has no CRS
};

// The largest raster ReadRaster accepts, in cells.
inline constexpr double kMaxRasterCells = 4e8;

// Reads band 1 of any raster GDAL opens. `what` names the scene key in errors. Throws InputError
// (file missing or unreadable, rotated or south-up geotransform, more than kMaxRasterCells cells).
Raster ReadRaster(const std::string& path, const std::string& what);

// The same, in the CRS `target_crs_wkt`: a raster with a CRS other than the target is warped to it
// by GDAL (nearest neighbour, so every value is a value of the file; cells off it are NaN) on the
// grid GDAL suggests (about the file's resolution, north-up), and *reprojected_from (when given)
// gets the file's CRS. A raster without CRS, or an empty target, is read as it is.
Raster ReadRasterIn(const std::string& path, const std::string& target_crs_wkt,
                    const std::string& what, std::string* reprojected_from);

// True when two WKT CRS definitions describe the same CRS.
bool SameCrs(const std::string& a_wkt, const std::string& b_wkt);

// True when a WKT CRS is geographic (coordinates in degrees, not metres); false when empty.
bool IsGeographicCrs(const std::string& crs_wkt);

// A CRS for messages: "EPSG:31287 (MGI / Austria Lambert)", its name alone when it has no EPSG
// code, "no CRS" when empty.
std::string DescribeCrs(const std::string& crs_wkt);

// "EPSG:326zz" or "EPSG:327zz": the WGS 84 / UTM zone holding the point (lon, lat) in degrees, or
// "" when (lon, lat) is not a point UTM covers (|lat| > 84 or |lon| > 180).
std::string UtmEpsgFor(double lon_deg, double lat_deg);

// The GDAL geotransform of a grid whose nodes are cell centres (north-up).
std::array<double, 6> GeoTransformOf(const GridGeometry& grid);

// The layout of written rasters: a tiled GeoTIFF, or a Cloud-Optimised GeoTIFF (GDAL's COG driver:
// tiles of 512 x 512, nearest-neighbour overviews down to one tile, header first, so that a
// viewer reads only what it shows).
enum class RasterFormat { kGeoTiff, kCog };
// "gtiff", "cog": [output] raster_format and summary.json's raster_output read this one list.
extern const EnumNames kRasterFormatNames;
const char* ToString(RasterFormat format);

// What a written raster says about itself: the band's description and unit
// (GDALRasterBand::SetDescription / SetUnitType) and dataset metadata items (name, value).
struct RasterMetadata {
  std::string description;
  std::string unit = {};
  std::vector<std::pair<std::string, std::string>> items = {};
};

// Writes a one-band Float32 (or, for counts, Int32) GeoTIFF (deflate-compressed, tiled) on `grid` with `crs_wkt` (may be
// empty), atomically, in `format`. `nodata` is set when has_nodata. The same arguments give the
// same bytes (nothing depends on the time or the machine).
void WriteGeoTiff(const std::string& path, const GridGeometry& grid, const std::string& crs_wkt,
                  const std::vector<float>& values, bool has_nodata, double nodata,
                  const RasterMetadata& metadata, RasterFormat format = RasterFormat::kGeoTiff);
void WriteGeoTiff(const std::string& path, const GridGeometry& grid, const std::string& crs_wkt,
                  const std::vector<std::int32_t>& values, bool has_nodata, double nodata,
                  const RasterMetadata& metadata, RasterFormat format = RasterFormat::kGeoTiff);

// Rasterises polygons onto the nodes of `grid` (GDAL's rasteriser): a node takes burn[k] of the
// last polygon k whose inside holds it (later polygons over earlier ones), else -1. Each polygon is
// its rings, the outer ring first, then holes, in the grid's coordinates.
std::vector<int> RasterisePolygons(
    const GridGeometry& grid,
    const std::vector<std::vector<std::vector<Eigen::Vector2d>>>& polygons,
    const std::vector<int>& burn);

// Makes sure GDAL's drivers are registered (idempotent, thread-safe).
void RegisterGdal();

}  // namespace talus::io
