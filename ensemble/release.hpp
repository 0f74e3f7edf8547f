#pragma once
// Where and how rocks start: release points, lines and polygons, and the per-rock start state drawn
// from the rock's own random stream (seed, rock index), so that runs are reproducible.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "solver/scene.hpp"
#include "solver/state.hpp"

namespace talus::ensemble {

// One release: a point, a polyline (start points uniform along its length) or a polygon (start
// points uniform over its area; rings after the first are holes). Map coordinates, m.
struct ReleaseGeometry {
  enum class Kind { kPoint, kLine, kPolygon };
  Kind kind = Kind::kPoint;
  std::vector<std::vector<Eigen::Vector2d>> rings;  // point: one ring of one vertex; line: one ring
};

// One run of an experiment campaign or a documented event: a release state of its own, with its
// own block. Positions in map coordinates (m), velocities in the world frame.
struct ReleaseRun {
  std::string id;  // e.g. the trajectory_id of a run table; unique within a spec
  Eigen::Vector2d xy_m = Eigen::Vector2d::Zero();
  std::optional<double> z_m;       // centre of mass height; else height_m above the ground
  std::optional<double> height_m;  // as ReleaseSpec::height_m (and its reference); else that
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();
  int block = -1;  // index into ReleaseSpec::blocks; -1: the scene's rock
  // Measured orientation of the shape as given (w, x, y, z); nullopt: the spec's orientation
  // (uniform on SO(3) per rock unless it fixes one).
  std::optional<Eigen::Quaterniond> orientation;
};

// The knobs of a block's shape that a calibration may change (calibration/parameters.hpp), and
// the seed of its random hull. NaN where the shape has no such knob: a box has no roughness, a
// scanned hull no size.
struct ShapeKnobs {
  double roughness = std::numeric_limits<double>::quiet_NaN();  // built-in rock, 0 .. 0.5
  // Bounding box (m) of a built-in box, ellipsoid, rock or EOTA block.
  Eigen::Vector3d size_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  std::uint64_t shape_seed = 0;  // of a built-in rock's random points
};

// Makes a block's shape from knobs. Throws talus::InputError for knobs that give no usable rock
// (e.g. a mass that makes the density of a smaller block impossible). Thread-safe.
using ShapeMaker = std::function<RockShape(const ShapeKnobs& knobs)>;

// A named rock shape that runs refer to (e.g. the blocks of an experiment campaign).
struct Block {
  std::string id;
  std::shared_ptr<const RockShape> shape;
  ShapeKnobs knobs;  // what `shape` was made from
  ShapeMaker make;   // the same block with other knobs; empty: the shape is fixed
};

// The volumes of the rocks of a release (block sizes): each rock's shape is scaled at its density
// to a volume drawn from its own stream (seed, rock), so that an ensemble is a population of sizes
// as a rockfall inventory describes it. The quantile V(u) of u uniform on [0, 1):
//  - fixed: every rock keeps its shape's volume (the default);
//  - uniform on [min_m3, max_m3];
//  - log-normal: ln V normal with median ln(median_m3) and standard deviation sigma, truncated to
//    [min_m3, max_m3] (0 and infinity: not truncated);
//  - power law: the cumulative frequency of inventories, N(>= V) proportional to V^-exponent,
//    on [min_m3, max_m3] (a truncated Pareto distribution; e.g. Dussauge et al. 2003, JGR 108(B6),
//    exponents 0.4-0.7 for rockfall volumes).
struct VolumeDistribution {
  enum class Kind { kFixed, kUniform, kLogNormal, kPowerLaw };
  Kind kind = Kind::kFixed;
  double min_m3 = 0, max_m3 = std::numeric_limits<double>::infinity();
  double median_m3 = 0, sigma = 0;  // log-normal
  double exponent = 0;              // power law, > 0
  // The volume at cumulative probability u in [0, 1] (not for kFixed).
  double Quantile(double u) const;
  // False, naming the key and value, when a bound or parameter is out of range.
  bool IsValid(std::string* why) const;
};

// "fixed", "uniform", "lognormal", "power_law".
const char* ToString(VolumeDistribution::Kind kind);

struct ReleaseSpec {
  static constexpr long kMaxTotalRocks = 1'000'000'000;  // rocks in one run, all releases together

  // Where rocks start: either geometries (points, lines, polygons) or runs, never both.
  std::vector<ReleaseGeometry> releases;
  std::vector<ReleaseRun> runs;
  std::vector<Block> blocks;  // shapes the runs name
  // When set, every rock gets a shape of its own: shape_per_rock(block, shape seed) with the
  // block of its run (an element of `blocks`; null: the scene's rock) and a seed that depends on
  // (seed, rock) only. It is called from worker threads and must be thread-safe; a bad shape is
  // an exception.
  std::function<RockShape(const Block* block, std::uint64_t shape_seed)> shape_per_rock;
  long rocks_per_release = 1;  // per release geometry or per run (when release_first_rock is empty)
  // When not empty: release r holds rocks [release_first_rock[r], release_first_rock[r + 1])
  // (release_count() + 1 entries from 0, e.g. rocks per m2 of each polygon); set it with
  // SetRocksPerRelease.
  std::vector<long> release_first_rock;
  double height_m = 1.0;  // height above the ground at release (before any raise), see below
  // What height_m measures: the centre of mass above the ground below it, or the lowest hull
  // vertex (in the start orientation) above the ground below that vertex.
  enum class HeightReference { kCentreOfMass, kLowestPoint };
  HeightReference height_reference = HeightReference::kCentreOfMass;
  // Start points of lines and polygons only where the terrain has a height (the parts over
  // nodata or off the DEM are left out); false: such releases are an error (see PointOffTerrain).
  bool clip_to_dem = false;
  // Fixed orientation of the shape as given (w, x, y, z), or nullopt for uniform on SO(3).
  std::optional<Eigen::Quaterniond> orientation;
  Eigen::Vector3d velocity_m_s = Eigen::Vector3d::Zero();            // world frame
  Eigen::Vector3d angular_velocity_rad_s = Eigen::Vector3d::Zero();  // world frame
  std::uint64_t seed = 1;
  // The rocks' volumes (block sizes); fixed by default.
  VolumeDistribution volume;

  // Number of release geometries or runs.
  long release_count() const {
    return static_cast<long>(runs.empty() ? releases.size() : runs.size());
  }
  long total_rocks() const {
    return release_first_rock.empty() ? rocks_per_release * release_count()
                                      : release_first_rock.back();
  }
  // The same number of rocks for every release.
  void SetRocksPerRelease(long rocks);
  // Rocks of each release (one count per release geometry or run).
  void SetRocksPerRelease(const std::vector<long>& rocks);
  // Index of the release geometry or run of a rock: rocks of one release are consecutive.
  int ReleaseOf(long rock) const;
  // The first rock of a release and how many it has.
  long FirstRockOf(int release) const;
  long RocksOf(int release) const;
  // The run id of a rock's release: the run's id, or the release's index for geometries.
  std::string ReleaseName(int release) const;
  // False, naming the field and value, when a value is out of range (more than kMaxTotalRocks
  // rocks in all) or a geometry is degenerate (a line of zero length, a polygon whose holes leave
  // no area).
  bool IsValid(std::string* why) const;
};

// The smallest fraction of its bounding box a release polygon (net of holes) may cover: start
// points are drawn in the box and kept when inside.
inline constexpr double kMinPolygonFill = 1e-3;

// "" when rocks can start on `g`, else what is wrong with it: no or non-finite coordinates, a line
// of zero or non-finite length, a polygon of fewer than 3 points, of non-finite area, whose holes
// cover it, or a sliver (covering less than kMinPolygonFill of its bounding box).
std::string ReleaseGeometryProblem(const ReleaseGeometry& g);

// Whether p lies inside the polygon of `rings` by the even-odd rule over all rings, so that inner
// rings are holes.
bool InsidePolygon(const std::vector<std::vector<Eigen::Vector2d>>& rings,
                   const Eigen::Vector2d& p);

// A point of `release` where the terrain has no height (outside the DEM or on a nodata cell), or
// nullopt when rocks can start anywhere on it: its vertices, its lines or rings (checked every
// quarter cell) and, for a polygon, the centres of the cells without height that it covers.
std::optional<Eigen::Vector2d> PointOffTerrain(const Terrain& terrain,
                                               const ReleaseGeometry& release);

// Whether rocks can start at (x, y): the terrain has a height there.
bool OnTerrain(const Terrain& terrain, const Eigen::Vector2d& p);

// The fraction of `release` (of a line's length, or a polygon's area) over which the terrain has a
// height, estimated on a lattice of at least 4 points per cell and 200 x 200 points (lines: every
// 1/4 cell and 10^4 points); 1 for a point on the terrain, 0 off it.
double FractionOnTerrain(const Terrain& terrain, const ReleaseGeometry& release);

// The area of a polygon net of its holes (m2); 0 for points and lines.
double ReleaseArea(const ReleaseGeometry& release);

// A rock ready to run: its shape and start state.
struct ReleasedRock {
  std::shared_ptr<const RockShape> shape;  // the scene's rock, a block's, or the rock's own
  RockState start;                         // raised so that no vertex is below ground
  double lift_m = 0;                       // how far it was raised (m, >= 0)
};

// The one way to release rock `rock` (0-based, releases one after another): its shape, position
// on its release (or its run's position; only where the terrain has a height with clip_to_dem)
// with the centre of mass or the lowest vertex height_m above the ground (height_reference; or at
// the run's z_m), orientation (fixed, or uniform on SO(3)), velocities; then raised until no
// vertex is below the terrain. Depends on (spec.seed, rock) only. `scene` must outlive the result
// when the rock uses the scene's shape.
ReleasedRock Release(const Scene& scene, const ReleaseSpec& spec, long rock);

// The seed of rock `rock`'s own shape (see ReleaseSpec::shape_per_rock): SplitMix64 mixing of
// (seed, rock), independent of the rock's orientation stream.
std::uint64_t RockShapeSeed(std::uint64_t seed, long rock);

// The stream of a rock's volume draw, RockRandom(RockShapeSeed(seed, rock), kRockVolumeStream):
// independent of its orientation and of its shape's points.
inline constexpr std::uint64_t kRockVolumeStream = 0x524f434b564f4c55;  // "ROCKVOLU"

// The volume rock `rock` of `spec` is scaled to (spec.volume not fixed).
double RockVolume(const ReleaseSpec& spec, long rock);

}  // namespace talus::ensemble
