#pragma once
// Terrain: a heightfield on a regular grid with bilinear heights, and a ground-category grid.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace talus {

// A regular grid of nodes: node (i, j) sits at (x0_m + i dx_m, y0_m + j dy_m), i along x, j along
// y.
struct GridGeometry {
  int nx = 0;
  int ny = 0;
  double x0_m = 0;  // x of node (0, 0)
  double y0_m = 0;  // y of node (0, 0)
  double dx_m = 1;  // node spacing along x, > 0
  double dy_m = 1;  // node spacing along y, > 0

  double x_max_m() const { return x0_m + (nx - 1) * dx_m; }
  double y_max_m() const { return y0_m + (ny - 1) * dy_m; }
  bool IsValid(std::string* why) const;
};

// Heights at grid nodes, row j (y) after row j-1: z[j * nx + i]. NaN marks nodata.
struct Heightfield {
  GridGeometry grid;
  std::vector<double> z_m;
};

// Per-cell ground-category indices (into the scene's GroundTable): cell (i, j) covers
// [x0 + (i - 1/2) dx, x0 + (i + 1/2) dx) x [...], i.e. the grid's nodes are cell centres.
// kNoGround in a cell means "use the terrain's default category".
struct GroundGrid {
  static constexpr std::uint8_t kNoGround = 255;
  GridGeometry grid;
  std::vector<std::uint8_t> index;
};

// What the terrain says about one horizontal position.
struct TerrainSample {
  double height_m = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, upward, normal of the bilinear patch
};

// A hierarchy of square blocks of the DEM's cells, 2^k x 2^k cells for k = kFirstLevel ..
// kLastLevel (fewer at the grid's far edges), each with a plane and the largest vertical departure
// of the block's nodes from it (NaN when one is nodata). The bilinear terrain less a plane is
// bilinear in each cell, so it departs from the block's plane nowhere in the block by more than at
// a node: Terrain::PlaneAround bounds a large box by the few blocks that cover it instead of every
// cell.
struct PlanePyramid {
  static constexpr int kFirstLevel = 2;  // blocks of 4 x 4 cells
  static constexpr int kLastLevel = 8;   // blocks of 256 x 256 cells
  struct Block {
    double z_m = 0;         // the plane's height at the block's centre
    double slope_x = 0;     // dz/dx
    double slope_y = 0;     // dz/dy
    double residual_m = 0;  // largest |node height - plane| over the block's nodes; NaN: nodata
  };
  struct Level {
    int cells = 0;              // block side, cells
    int nbx = 0, nby = 0;       // blocks along x and y
    std::vector<Block> blocks;  // row after row along y
  };
  std::vector<Level> levels;  // levels[k - kFirstLevel]; only those the grid can hold
  static PlanePyramid Build(const Heightfield& heights);
};

// The heights and the ground grid are immutable once set and shared between copies (a copy of a
// Terrain, and so of a Scene, costs two reference counts, not the DEM): calibration runs many
// scenes that differ only in their ground table.
class Terrain {
 public:
  Terrain();
  // heights: the DEM; default_ground: ground index used where there is no ground grid or it has
  // no value.
  Terrain(Heightfield heights, int default_ground);

  // Optional ground-category grid on its own geometry.
  void SetGroundGrid(GroundGrid ground);

  // False outside the grid or where a corner of the cell is nodata.
  bool Sample(double x_m, double y_m, TerrainSample* out) const;
  // The height alone (the contact test's fast path); false as for Sample.
  bool Height(double x_m, double y_m, double* height_m) const;
  // Sample for a point (x, y, z) that may lie below the terrain, its normal taken only if it does:
  // false as for Sample and where z is at or above the height (where a gap (z - h) n_z is not
  // negative). The same bits as Sample where true.
  bool SampleBelow(double x_m, double y_m, double z_m, TerrainSample* out) const;

  // The cell holding a point: its lower and upper rows of node heights (corners [0] and [1] of
  // each) and the point's local coordinates (u, w) in [0, 1]^2. For a height that may need its
  // normal afterwards (a vertex found closed) without locating the point twice: Height and Sample
  // are HeightIn and NormalIn of the located cell, so the values are the same bits.
  struct Cell {
    const double* row0;
    const double* row1;
    double u, w;
  };
  // False outside the grid.
  bool Locate(double x_m, double y_m, Cell* cell) const;
  // The bilinear height in a located cell (NaN at a nodata corner) and the unit upward normal.
  static double HeightIn(const Cell& c) {
    const double lower = c.row0[0] + c.u * (c.row0[1] - c.row0[0]);
    const double upper = c.row1[0] + c.u * (c.row1[1] - c.row1[0]);
    return lower + c.w * (upper - lower);
  }
  Eigen::Vector3d NormalIn(const Cell& c) const;

  // Ground index at a horizontal position (the default where the ground grid has none).
  int GroundAt(double x_m, double y_m) const;

  // The tangent plane of the terrain at (x, y) and how far the terrain departs from it, vertically,
  // anywhere in the box [x - r, x + r] x [y - r, y + r]: |h(p) - plane(p)| <= deviation_m there.
  // A box over at most kExactCells cells per side: in each cell that holds a point of the box,
  // h - plane is bilinear, so its extremes over the part of the box in that cell are at that part's
  // corners: deviation_m is the largest of those, the tightest such bound. A larger box (a fine
  // DEM): the at most 2 x 2 blocks of the smallest PlanePyramid level whose blocks are as wide as
  // the box, each adding its residual to the largest departure of its plane from the tangent plane
  // at the corners of the box's part in it; a bound whose cost does not grow with the DEM's
  // resolution. Plus 1e-6 m for rounding. False when the box reaches beyond the grid or a cell that
  // holds a point of it (a block, for the pyramid's bound) has a nodata corner.
  struct LocalPlane {
    TerrainSample at;    // height and normal at (x, y)
    double slope_x = 0;  // dh/dx
    double slope_y = 0;  // dh/dy
    double deviation_m = 0;
  };
  bool PlaneAround(double x_m, double y_m, double r_m, LocalPlane* out) const;
  static constexpr int kExactCells = 4;

  // A box of horizontal positions, m.
  struct Box {
    double x_lo_m, x_hi_m, y_lo_m, y_hi_m;
  };
  // The plane z = z_m + slope_x (x - x_m) + slope_y (y - y_m).
  struct Plane {
    double x_m, y_m, z_m, slope_x, slope_y;
  };
  // An upper bound of the terrain's height above `plane` over a box: the largest over the nodes of
  // every cell that holds a point of the box (a bilinear patch's height above a plane lies between
  // its values at the cell's corners). False when the box reaches beyond the grid or a cell that
  // holds a point of it has a nodata corner.
  bool MaxAbovePlane(const Box& box, const Plane& plane, double* above_m) const;

  const Heightfield& heights() const { return *heights_; }
  // The heights, shared: what holds them keeps them (and their address) alive.
  const std::shared_ptr<const Heightfield>& shared_heights() const { return heights_; }
  int default_ground() const { return default_ground_; }
  bool has_ground_grid() const { return !ground_->index.empty(); }
  const GroundGrid& ground_grid() const { return *ground_; }
  // True when this terrain and `other` share one heightfield in memory (copies do).
  bool SharesHeightsWith(const Terrain& other) const { return heights_ == other.heights_; }

  // Checks the grid, array sizes and that there is at least one valid cell.
  bool IsValid(std::string* why) const;

 private:
  // Shared, immutable. The hot path reads the cached grid and pointers below, not through these.
  std::shared_ptr<const Heightfield> heights_;
  std::shared_ptr<const GroundGrid> ground_;
  std::shared_ptr<const PlanePyramid> pyramid_;
  GridGeometry grid_;                           // heights_->grid
  const double* z_ = nullptr;                   // heights_->z_m.data()
  GridGeometry ground_geometry_;                // ground_->grid
  const std::uint8_t* ground_index_ = nullptr;  // ground_->index.data(); null: no ground grid
  double inv_dx_ = 1, inv_dy_ = 1;              // 1 / node spacing, 1/m
  int default_ground_ = 0;
};

// The analytic test slope: an inclined plane falling along +x followed by a flat runout.
// x in [0, slope_length + runout], y in [-width/2, width/2]; height (slope_length - x) tan(slope)
// on the slope and 0 on the runout.
struct PlaneSpec {
  double slope_deg = 40;
  double slope_length_m = 200;  // horizontal length of the inclined part
  double runout_m = 150;        // horizontal length of the flat part
  double width_m = 100;
  double cell_m = 2;
  bool IsValid(std::string* why) const;
};
Heightfield MakePlaneHeightfield(const PlaneSpec& spec);

}  // namespace talus
