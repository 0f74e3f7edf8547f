#include "solver/terrain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "common/rounding.hpp"

namespace talus {
namespace {

// Allowance on LocalPlane::deviation_m for the rounding of heights evaluated at different points
// (a few units in the last place of heights up to 1e4 m), m.
constexpr double kPlaneRounding_m = 1e-6;

}  // namespace

bool GridGeometry::IsValid(std::string* why) const {
  std::ostringstream msg;
  if (nx < 2 || ny < 2)
    msg << "grid of " << nx << " x " << ny << " nodes: at least 2 x 2 are needed";
  else if (!(dx_m > 0) || !(dy_m > 0) || !std::isfinite(dx_m) || !std::isfinite(dy_m))
    msg << "grid spacing " << dx_m << " x " << dy_m << " m must be positive and finite";
  else if (!std::isfinite(x0_m) || !std::isfinite(y0_m))
    msg << "grid origin is not finite";
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

Terrain::Terrain()
    : heights_(std::make_shared<const Heightfield>()),
      ground_(std::make_shared<const GroundGrid>()),
      grid_(heights_->grid) {}

PlanePyramid PlanePyramid::Build(const Heightfield& heights) {
  PlanePyramid pyramid;
  const GridGeometry& g = heights.grid;
  if (g.nx < 2 || g.ny < 2 || heights.z_m.size() != static_cast<std::size_t>(g.nx) * g.ny)
    return pyramid;
  auto z = [&](int i, int j) { return heights.z_m[static_cast<std::size_t>(j) * g.nx + i]; };
  const int cells_x = g.nx - 1, cells_y = g.ny - 1;
  for (int k = kFirstLevel; k <= kLastLevel; ++k) {
    Level level;
    level.cells = 1 << k;
    // A level whose blocks are twice those of one that already held the whole grid adds nothing.
    if (level.cells / 2 >= std::max(cells_x, cells_y) && k > kFirstLevel) break;
    level.nbx = (cells_x + level.cells - 1) / level.cells;
    level.nby = (cells_y + level.cells - 1) / level.cells;
    level.blocks.resize(static_cast<std::size_t>(level.nbx) * level.nby);
    for (int bj = 0; bj < level.nby; ++bj) {
      const int j0 = bj * level.cells, j1 = std::min(j0 + level.cells, cells_y);
      for (int bi = 0; bi < level.nbx; ++bi) {
        const int i0 = bi * level.cells, i1 = std::min(i0 + level.cells, cells_x);
        Block& b = level.blocks[static_cast<std::size_t>(bj) * level.nbx + bi];
        // The plane through the mean of the corners with the mean slopes of the block's edges.
        const double z00 = z(i0, j0), z10 = z(i1, j0), z01 = z(i0, j1), z11 = z(i1, j1);
        b.slope_x = ((z10 - z00) + (z11 - z01)) / (2 * (i1 - i0) * g.dx_m);
        b.slope_y = ((z01 - z00) + (z11 - z10)) / (2 * (j1 - j0) * g.dy_m);
        b.z_m = 0.25 * (z00 + z10 + z01 + z11);
        const double ic = 0.5 * (i0 + i1), jc = 0.5 * (j0 + j1);
        double residual = 0;
        for (int j = j0; j <= j1 && !std::isnan(residual); ++j)
          for (int i = i0; i <= i1; ++i) {
            const double d =
                z(i, j) - (b.z_m + b.slope_x * (i - ic) * g.dx_m + b.slope_y * (j - jc) * g.dy_m);
            if (std::isnan(d)) {
              residual = std::numeric_limits<double>::quiet_NaN();
              break;
            }
            residual = std::max(residual, std::abs(d));
          }
        b.residual_m = residual;
      }
    }
    pyramid.levels.push_back(std::move(level));
  }
  return pyramid;
}

Terrain::Terrain(Heightfield heights, int default_ground)
    : heights_(std::make_shared<const Heightfield>(std::move(heights))),
      ground_(std::make_shared<const GroundGrid>()),
      pyramid_(std::make_shared<const PlanePyramid>(PlanePyramid::Build(*heights_))),
      grid_(heights_->grid),
      z_(heights_->z_m.data()),
      inv_dx_(1.0 / grid_.dx_m),
      inv_dy_(1.0 / grid_.dy_m),
      default_ground_(default_ground) {}

void Terrain::SetGroundGrid(GroundGrid ground) {
  ground_ = std::make_shared<const GroundGrid>(std::move(ground));
  ground_geometry_ = ground_->grid;
  ground_index_ = ground_->index.empty() ? nullptr : ground_->index.data();
}

bool Terrain::Locate(double x_m, double y_m, Cell* cell) const {
  const GridGeometry& g = grid_;
  const double fx = (x_m - g.x0_m) * inv_dx_;
  const double fy = (y_m - g.y0_m) * inv_dy_;
  if (!(fx >= 0 && fy >= 0 && fx <= g.nx - 1 && fy <= g.ny - 1)) return false;
  const int i = std::min(static_cast<int>(fx), g.nx - 2);
  const int j = std::min(static_cast<int>(fy), g.ny - 2);
  cell->row0 = z_ + static_cast<std::size_t>(j) * g.nx + i;
  cell->row1 = cell->row0 + g.nx;
  cell->u = fx - i;
  cell->w = fy - j;
  return true;
}

bool Terrain::Height(double x_m, double y_m, double* height_m) const {
  Cell c;
  if (!Locate(x_m, y_m, &c)) return false;
  *height_m = HeightIn(c);
  return !std::isnan(*height_m);  // a nodata corner
}

Eigen::Vector3d Terrain::NormalIn(const Cell& c) const {
  const double z00 = c.row0[0], z10 = c.row0[1], z01 = c.row1[0], z11 = c.row1[1];
  const double lower = z00 + c.u * (z10 - z00);
  const double upper = z01 + c.u * (z11 - z01);
  const double hx = ((z10 - z00) * (1 - c.w) + (z11 - z01) * c.w) * inv_dx_;
  const double hy = (upper - lower) * inv_dy_;
  return Eigen::Vector3d(-hx, -hy, 1.0) / std::sqrt(hx * hx + hy * hy + 1.0);
}

bool Terrain::Sample(double x_m, double y_m, TerrainSample* out) const {
  Cell c;
  if (!Locate(x_m, y_m, &c)) return false;
  const double h = HeightIn(c);
  if (std::isnan(h)) return false;  // a nodata corner
  out->height_m = h;
  out->normal = NormalIn(c);
  return true;
}

bool Terrain::SampleBelow(double x_m, double y_m, double z_m, TerrainSample* out) const {
  Cell c;
  if (!Locate(x_m, y_m, &c)) return false;
  const double h = HeightIn(c);
  if (std::isnan(h) || z_m >= h) return false;  // a nodata corner, or at or above the terrain
  out->height_m = h;
  out->normal = NormalIn(c);
  return true;
}

int Terrain::GroundAt(double x_m, double y_m) const {
  if (!ground_index_) return default_ground_;
  const GridGeometry& g = ground_geometry_;
  const long i = RoundHalfAway((x_m - g.x0_m) / g.dx_m);
  const long j = RoundHalfAway((y_m - g.y0_m) / g.dy_m);
  if (i < 0 || j < 0 || i >= g.nx || j >= g.ny) return default_ground_;
  const std::uint8_t index = ground_index_[static_cast<std::size_t>(j) * g.nx + i];
  return index == GroundGrid::kNoGround ? default_ground_ : index;
}

// The bilinear height of a cell, less a plane, is bilinear in the cell's coordinates: over a
// rectangle of the cell it is largest and smallest at the rectangle's corners.
bool Terrain::PlaneAround(double x_m, double y_m, double r_m, LocalPlane* out) const {
  const GridGeometry& g = grid_;
  const double fx_lo = (x_m - r_m - g.x0_m) * inv_dx_, fx_hi = (x_m + r_m - g.x0_m) * inv_dx_;
  const double fy_lo = (y_m - r_m - g.y0_m) * inv_dy_, fy_hi = (y_m + r_m - g.y0_m) * inv_dy_;
  if (!(fx_lo >= 0 && fy_lo >= 0 && fx_hi <= g.nx - 1 && fy_hi <= g.ny - 1)) return false;
  if (!Sample(x_m, y_m, &out->at)) return false;
  const Eigen::Vector3d& n = out->at.normal;
  out->slope_x = -n.x() / n.z();
  out->slope_y = -n.y() / n.z();
  const double span_cells = std::max(fx_hi - fx_lo, fy_hi - fy_lo);
  if (span_cells > kExactCells && pyramid_) {
    for (const PlanePyramid::Level& level : pyramid_->levels) {
      if (level.cells < span_cells) continue;
      // The box lies in at most 2 x 2 blocks of this level.
      const int bi_lo = static_cast<int>(fx_lo) / level.cells;
      const int bj_lo = static_cast<int>(fy_lo) / level.cells;
      const int bi_hi = std::min(static_cast<int>(fx_hi) / level.cells, level.nbx - 1);
      const int bj_hi = std::min(static_cast<int>(fy_hi) / level.cells, level.nby - 1);
      double deviation = 0;
      for (int bj = bj_lo; bj <= bj_hi; ++bj) {
        const double j0 = bj * level.cells, j1 = std::min(j0 + level.cells, g.ny - 1.0);
        const double w_corners[2] = {std::max(fy_lo, j0), std::min(fy_hi, j1)};
        for (int bi = bi_lo; bi <= bi_hi; ++bi) {
          const PlanePyramid::Block& b =
              level.blocks[static_cast<std::size_t>(bj) * level.nbx + bi];
          if (std::isnan(b.residual_m)) return false;  // a nodata node: no bound
          const double i0 = bi * level.cells, i1 = std::min(i0 + level.cells, g.nx - 1.0);
          const double u_corners[2] = {std::max(fx_lo, i0), std::min(fx_hi, i1)};
          const double ic = 0.5 * (i0 + i1), jc = 0.5 * (j0 + j1);
          for (double fy : w_corners)
            for (double fx : u_corners) {
              const double block =
                  b.z_m + b.slope_x * (fx - ic) * g.dx_m + b.slope_y * (fy - jc) * g.dy_m;
              const double plane = out->at.height_m + out->slope_x * (g.x0_m + fx * g.dx_m - x_m) +
                                   out->slope_y * (g.y0_m + fy * g.dy_m - y_m);
              deviation = std::max(deviation, b.residual_m + std::abs(block - plane));
            }
        }
      }
      out->deviation_m = deviation + kPlaneRounding_m;
      return true;
    }
  }
  const int i_lo = std::min(static_cast<int>(fx_lo), g.nx - 2);
  const int i_hi = std::min(static_cast<int>(fx_hi), g.nx - 2);
  const int j_lo = std::min(static_cast<int>(fy_lo), g.ny - 2);
  const int j_hi = std::min(static_cast<int>(fy_hi), g.ny - 2);
  double deviation = 0;
  for (int j = j_lo; j <= j_hi; ++j) {
    const double* row0 = z_ + static_cast<std::size_t>(j) * g.nx;
    const double* row1 = row0 + g.nx;
    const double w_corners[2] = {std::max(fy_lo - j, 0.0), std::min(fy_hi - j, 1.0)};
    for (int i = i_lo; i <= i_hi; ++i) {
      const double z00 = row0[i], z10 = row0[i + 1], z01 = row1[i], z11 = row1[i + 1];
      if (std::isnan(z00 + z10 + z01 + z11)) return false;  // a nodata corner: no bound
      const double u_corners[2] = {std::max(fx_lo - i, 0.0), std::min(fx_hi - i, 1.0)};
      for (double w : w_corners) {
        const double dy = g.y0_m + (j + w) * g.dy_m - y_m;
        for (double u : u_corners) {
          const double lower = z00 + u * (z10 - z00);
          const double upper = z01 + u * (z11 - z01);
          const double dx = g.x0_m + (i + u) * g.dx_m - x_m;
          const double plane = out->at.height_m + out->slope_x * dx + out->slope_y * dy;
          deviation = std::max(deviation, std::abs(lower + w * (upper - lower) - plane));
        }
      }
    }
  }
  out->deviation_m = deviation + kPlaneRounding_m;
  return true;
}

bool Terrain::MaxAbovePlane(const Box& box, const Plane& plane, double* above_m) const {
  const GridGeometry& g = grid_;
  const double fx_lo = (box.x_lo_m - g.x0_m) * inv_dx_, fx_hi = (box.x_hi_m - g.x0_m) * inv_dx_;
  const double fy_lo = (box.y_lo_m - g.y0_m) * inv_dy_, fy_hi = (box.y_hi_m - g.y0_m) * inv_dy_;
  if (!(fx_lo >= 0 && fy_lo >= 0 && fx_hi <= g.nx - 1 && fy_hi <= g.ny - 1)) return false;
  // The cell of a point is (floor(f), floor(f) + 1), the last one where f is the last node.
  const int i_lo = std::min(static_cast<int>(fx_lo), g.nx - 2);
  const int j_lo = std::min(static_cast<int>(fy_lo), g.ny - 2);
  const int i_hi = std::min(static_cast<int>(fx_hi) + 1, g.nx - 1);
  const int j_hi = std::min(static_cast<int>(fy_hi) + 1, g.ny - 1);
  double above = -std::numeric_limits<double>::infinity();
  for (int j = j_lo; j <= j_hi; ++j) {
    const double* row = z_ + static_cast<std::size_t>(j) * g.nx;
    const double plane_row = plane.z_m + plane.slope_y * (g.y0_m + j * g.dy_m - plane.y_m);
    for (int i = i_lo; i <= i_hi; ++i) {
      if (std::isnan(row[i])) return false;
      above =
          std::max(above, row[i] - (plane_row + plane.slope_x * (g.x0_m + i * g.dx_m - plane.x_m)));
    }
  }
  *above_m = above;
  return true;
}

bool Terrain::IsValid(std::string* why) const {
  const Heightfield& heights = *heights_;
  const GridGeometry& g = heights.grid;
  if (!g.IsValid(why)) return false;
  if (heights.z_m.size() != static_cast<std::size_t>(g.nx) * g.ny) {
    if (why)
      *why = "heightfield has " + std::to_string(heights.z_m.size()) + " values for a " +
             std::to_string(g.nx) + " x " + std::to_string(g.ny) + " grid";
    return false;
  }
  for (double z : heights.z_m) {
    if (std::isinf(z)) {
      if (why) *why = "heightfield contains an infinite height";
      return false;
    }
  }
  if (std::all_of(heights.z_m.begin(), heights.z_m.end(), [](double z) { return std::isnan(z); })) {
    if (why) *why = "heightfield has no valid height (all nodata)";
    return false;
  }
  if (!ground_->index.empty()) {
    if (!ground_->grid.IsValid(why)) return false;
    if (ground_->index.size() != static_cast<std::size_t>(ground_->grid.nx) * ground_->grid.ny) {
      if (why) *why = "ground grid size does not match its geometry";
      return false;
    }
  }
  return true;
}

bool PlaneSpec::IsValid(std::string* why) const {
  std::ostringstream msg;
  if (!(slope_deg >= 0 && slope_deg < 89))
    msg << "slope_deg = " << slope_deg << " must be in [0, 89)";
  else if (!(slope_length_m >= 0 && std::isfinite(slope_length_m)))
    msg << "slope_length_m = " << slope_length_m << " must be >= 0";
  else if (!(runout_m >= 0 && std::isfinite(runout_m)))
    msg << "runout_m = " << runout_m << " must be >= 0";
  else if (!(width_m > 0 && std::isfinite(width_m)))
    msg << "width_m = " << width_m << " must be > 0";
  else if (!(cell_m > 0 && std::isfinite(cell_m)))
    msg << "cell_m = " << cell_m << " must be > 0";
  else if ((slope_length_m + runout_m) / cell_m < 1 || width_m / cell_m < 1)
    msg << "cell_m = " << cell_m << " is larger than the plane";
  else if ((slope_length_m + runout_m) / cell_m * (width_m / cell_m) > 4e8)
    msg << "cell_m = " << cell_m << " gives more than 4e8 nodes";
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

Heightfield MakePlaneHeightfield(const PlaneSpec& spec) {
  Heightfield hf;
  GridGeometry& g = hf.grid;
  g.nx =
      static_cast<int>(std::ceil((spec.slope_length_m + spec.runout_m) / spec.cell_m - 1e-9)) + 1;
  g.ny = static_cast<int>(std::ceil(spec.width_m / spec.cell_m - 1e-9)) + 1;
  g.dx_m = g.dy_m = spec.cell_m;
  g.x0_m = 0;
  g.y0_m = -0.5 * (g.ny - 1) * spec.cell_m;
  const double tan_slope = std::tan(spec.slope_deg * std::numbers::pi / 180.0);
  hf.z_m.resize(static_cast<std::size_t>(g.nx) * g.ny);
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i)
      hf.z_m[static_cast<std::size_t>(j) * g.nx + i] =
          std::max(0.0, spec.slope_length_m - i * spec.cell_m) * tan_slope;
  return hf;
}

}  // namespace talus
