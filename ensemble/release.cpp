#include "ensemble/release.hpp"

#include <boost/math/distributions/normal.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string_view>
#include <unordered_set>

#include "solver/random.hpp"
#include "solver/simulate.hpp"

namespace talus::ensemble {
namespace {

bool Fail(std::string* why, const std::string& message) {
  if (why) *why = message;
  return false;
}

double RingArea(const std::vector<Eigen::Vector2d>& ring) {
  double twice = 0;
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const Eigen::Vector2d& a = ring[k];
    const Eigen::Vector2d& b = ring[(k + 1) % ring.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return 0.5 * twice;
}

double LineLength(const std::vector<Eigen::Vector2d>& line) {
  double total = 0;
  for (std::size_t k = 1; k < line.size(); ++k) total += (line[k] - line[k - 1]).norm();
  return total;
}

Eigen::Vector2d PointOnLine(const std::vector<Eigen::Vector2d>& line, double u) {
  double target = u * LineLength(line);
  for (std::size_t k = 1; k < line.size(); ++k) {
    const double length = (line[k] - line[k - 1]).norm();
    if (target <= length && length > 0)
      return line[k - 1] + (target / length) * (line[k] - line[k - 1]);
    target -= length;
  }
  return line.back();
}

// A start point uniform along `line` where `keep` holds (rejection: ClipToDem releases cover at
// least kMinPolygonFill of their length, checked when the scene is loaded).
template <class Keep>
Eigen::Vector2d PointOnLine(const std::vector<Eigen::Vector2d>& line, RockRandom& random,
                            Keep keep) {
  Eigen::Vector2d p = line.front();
  for (int attempt = 0; attempt < 100000; ++attempt) {
    p = PointOnLine(line, random.Uniform());
    if (keep(p)) return p;
  }
  return p;
}

template <class Keep>
Eigen::Vector2d PointInPolygon(const std::vector<std::vector<Eigen::Vector2d>>& rings,
                               RockRandom& random, Keep keep) {
  Eigen::Vector2d lo = rings[0][0], hi = rings[0][0];
  for (const Eigen::Vector2d& v : rings[0]) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  // Rejection sampling in the bounding box. IsValid ensures the polygon (the part where `keep`
  // holds, checked when the scene is loaded) covers at least kMinPolygonFill of its box, so all
  // attempts fail with probability (1 - 1e-3)^1e5 < 1e-43.
  for (int attempt = 0; attempt < 100000; ++attempt) {
    const double u = random.Uniform(), v = random.Uniform();
    Eigen::Vector2d p(lo.x() + u * (hi.x() - lo.x()), lo.y() + v * (hi.y() - lo.y()));
    if (InsidePolygon(rings, p) && keep(p)) return p;
  }
  return rings[0][0];
}

// The bounding box of a polygon's outer ring.
void Bounds(const std::vector<Eigen::Vector2d>& ring, Eigen::Vector2d* lo, Eigen::Vector2d* hi) {
  *lo = *hi = ring[0];
  for (const Eigen::Vector2d& v : ring) {
    *lo = lo->cwiseMin(v);
    *hi = hi->cwiseMax(v);
  }
}

}  // namespace

void ReleaseSpec::SetRocksPerRelease(long rocks) {
  rocks_per_release = rocks;
  release_first_rock.clear();
}

void ReleaseSpec::SetRocksPerRelease(const std::vector<long>& rocks) {
  release_first_rock.assign(1, 0);
  for (long n : rocks) release_first_rock.push_back(release_first_rock.back() + n);
  rocks_per_release = rocks.empty() ? 1 : rocks.front();
}

int ReleaseSpec::ReleaseOf(long rock) const {
  if (release_first_rock.empty()) return static_cast<int>(rock / rocks_per_release);
  const auto after = std::upper_bound(release_first_rock.begin(), release_first_rock.end(), rock);
  return static_cast<int>(after - release_first_rock.begin()) - 1;
}

long ReleaseSpec::FirstRockOf(int release) const {
  return release_first_rock.empty() ? release * rocks_per_release
                                    : release_first_rock[static_cast<std::size_t>(release)];
}

long ReleaseSpec::RocksOf(int release) const {
  return release_first_rock.empty() ? rocks_per_release
                                    : release_first_rock[static_cast<std::size_t>(release) + 1] -
                                          release_first_rock[static_cast<std::size_t>(release)];
}

bool OnTerrain(const Terrain& terrain, const Eigen::Vector2d& p) {
  double height_m;
  return terrain.Height(p.x(), p.y(), &height_m);
}

double ReleaseArea(const ReleaseGeometry& release) {
  if (release.kind != ReleaseGeometry::Kind::kPolygon || release.rings.empty()) return 0;
  double holes = 0;
  for (std::size_t k = 1; k < release.rings.size(); ++k)
    holes += std::abs(RingArea(release.rings[k]));
  return std::abs(RingArea(release.rings[0])) - holes;
}

double FractionOnTerrain(const Terrain& terrain, const ReleaseGeometry& release) {
  const GridGeometry& grid = terrain.heights().grid;
  const double cell_m = std::min(grid.dx_m, grid.dy_m);
  const auto& ring = release.rings[0];
  long on = 0, all = 0;
  if (release.kind == ReleaseGeometry::Kind::kPoint) return OnTerrain(terrain, ring[0]) ? 1 : 0;
  if (release.kind == ReleaseGeometry::Kind::kLine) {
    const long n = std::clamp<long>(static_cast<long>(std::ceil(4 * LineLength(ring) / cell_m)),
                                    10000, 1000000);
    for (long k = 0; k < n; ++k, ++all)
      on += OnTerrain(terrain, PointOnLine(ring, (k + 0.5) / double(n))) ? 1 : 0;
    return double(on) / double(all);
  }
  Eigen::Vector2d lo, hi;
  Bounds(ring, &lo, &hi);
  const auto points = [&](double extent_m) {
    return std::clamp<long>(static_cast<long>(std::ceil(4 * extent_m / cell_m)), 200, 1000);
  };
  const long nx = points(hi.x() - lo.x()), ny = points(hi.y() - lo.y());
  for (long j = 0; j < ny; ++j)
    for (long i = 0; i < nx; ++i) {
      const Eigen::Vector2d p(lo.x() + (i + 0.5) / double(nx) * (hi.x() - lo.x()),
                              lo.y() + (j + 0.5) / double(ny) * (hi.y() - lo.y()));
      if (!InsidePolygon(release.rings, p)) continue;
      ++all;
      on += OnTerrain(terrain, p) ? 1 : 0;
    }
  return all == 0 ? 0 : double(on) / double(all);
}

std::string ReleaseSpec::ReleaseName(int release) const {
  return runs.empty() ? std::to_string(release) : runs[static_cast<std::size_t>(release)].id;
}

bool InsidePolygon(const std::vector<std::vector<Eigen::Vector2d>>& rings,
                   const Eigen::Vector2d& p) {
  bool inside = false;
  for (const auto& ring : rings) {
    for (std::size_t k = 0, l = ring.size() - 1; k < ring.size(); l = k++) {
      const Eigen::Vector2d& a = ring[k];
      const Eigen::Vector2d& b = ring[l];
      if ((a.y() > p.y()) != (b.y() > p.y()) &&
          p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
        inside = !inside;
    }
  }
  return inside;
}

bool ReleaseSpec::IsValid(std::string* why) const {
  std::ostringstream s;
  if (releases.empty() && runs.empty()) return Fail(why, "no release point, line, polygon or run");
  if (!releases.empty() && !runs.empty())
    return Fail(why, "release geometries and runs cannot be combined");
  if (std::string volume_why; !volume.IsValid(&volume_why))
    return Fail(why, "volume." + volume_why);
  for (const Block& block : blocks) {
    std::string shape_why;
    if (!block.shape) {
      s << "block " << block.id << " has no shape";
      return Fail(why, s.str());
    }
    if (!block.shape->IsValid(&shape_why)) {
      s << "block " << block.id << ": " << shape_why;
      return Fail(why, s.str());
    }
  }
  std::unordered_set<std::string_view> ids;  // a set: comparing each id with all before it was
                                             // quadratic (a 10^5-run table took a minute)
  for (const ReleaseRun& run : runs) {
    const auto bad = [&](const std::string& what) {
      s << "run " << run.id << ": " << what;
      return Fail(why, s.str());
    };
    if (run.id.empty()) return bad("empty id");
    if (!ids.insert(run.id).second) return bad("the id appears twice");
    if (!run.xy_m.allFinite() || (run.z_m && !std::isfinite(*run.z_m)))
      return bad("non-finite position");
    if (run.height_m && (!std::isfinite(*run.height_m) || *run.height_m < 0))
      return bad("height must be finite and >= 0");
    if (!run.velocity_m_s.allFinite() || !run.angular_velocity_rad_s.allFinite())
      return bad("non-finite velocity");
    if (run.block < -1 || run.block >= static_cast<int>(blocks.size()))
      return bad("unknown block index " + std::to_string(run.block));
    if (run.orientation &&
        (!run.orientation->coeffs().allFinite() || std::abs(run.orientation->norm() - 1) > 1e-6))
      return bad("orientation must be a unit quaternion [w, x, y, z]");
  }
  if (!release_first_rock.empty()) {
    if (static_cast<long>(release_first_rock.size()) != release_count() + 1 ||
        release_first_rock.front() != 0)
      return Fail(why, "release_first_rock does not match the releases");
    for (std::size_t r = 0; r + 1 < release_first_rock.size(); ++r)
      if (release_first_rock[r + 1] - release_first_rock[r] < 1) {
        s << "release " << r << " has " << release_first_rock[r + 1] - release_first_rock[r]
          << " rocks, must have >= 1";
        return Fail(why, s.str());
      }
    if (release_first_rock.back() > kMaxTotalRocks) {
      s << "rocks = " << release_first_rock.back() << " in all is more than " << kMaxTotalRocks;
      return Fail(why, s.str());
    }
  } else if (rocks_per_release < 1) {
    s << "rocks = " << rocks_per_release << " must be >= 1";
    return Fail(why, s.str());
  } else if (rocks_per_release > kMaxTotalRocks / release_count()) {
    s << "rocks = " << rocks_per_release << " per release x " << release_count()
      << " releases is more than " << kMaxTotalRocks << " rocks";
    return Fail(why, s.str());
  }
  if (!std::isfinite(height_m) || height_m < 0) {
    s << "height_m = " << height_m << " must be finite and >= 0";
    return Fail(why, s.str());
  }
  if (!velocity_m_s.allFinite()) return Fail(why, "velocity_m_s must be finite");
  if (!angular_velocity_rad_s.allFinite())
    return Fail(why, "angular_velocity_rad_s must be finite");
  if (orientation &&
      (!orientation->coeffs().allFinite() || std::abs(orientation->norm() - 1) > 1e-6)) {
    s << "orientation must be a unit quaternion [w, x, y, z] (norm " << orientation->norm() << ")";
    return Fail(why, s.str());
  }
  for (std::size_t r = 0; r < releases.size(); ++r)
    if (const std::string problem = ReleaseGeometryProblem(releases[r]); !problem.empty()) {
      s << "release " << r << ": " << problem;
      return Fail(why, s.str());
    }
  return true;
}

std::string ReleaseGeometryProblem(const ReleaseGeometry& g) {
  std::ostringstream s;
  if (g.rings.empty() || g.rings[0].empty()) return "no coordinates";
  for (const auto& ring : g.rings)
    for (const Eigen::Vector2d& v : ring)
      if (!v.allFinite()) return "a non-finite coordinate";
  if (g.kind == ReleaseGeometry::Kind::kLine) {
    const double length = LineLength(g.rings[0]);
    if (g.rings[0].size() < 2 || !(length > 0))
      return "a line needs at least 2 points and a positive length";
    if (!std::isfinite(length))
      return "coordinates out of range: the length of the line is not a finite number";
  }
  if (g.kind != ReleaseGeometry::Kind::kPolygon) return "";
  if (g.rings[0].size() < 3) return "a polygon needs at least 3 points";
  // Start points are drawn uniformly in the bounding box and kept when inside: the polygon must
  // cover a fair part of its box, or the draws would run out (kMinPolygonFill).
  double holes = 0;
  for (std::size_t k = 1; k < g.rings.size(); ++k) holes += std::abs(RingArea(g.rings[k]));
  const double area = std::abs(RingArea(g.rings[0])) - holes;
  Eigen::Vector2d lo = g.rings[0][0], hi = lo;
  for (const Eigen::Vector2d& v : g.rings[0]) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const double box = (hi - lo).prod();
  if (!std::isfinite(area) || !std::isfinite(box))
    return "coordinates out of range: the area of the polygon is not a finite number";
  if (g.rings.size() > 1 && area <= 0) return "the polygon's holes cover all of its area";
  if (!(area > kMinPolygonFill * box)) {
    s << "a sliver: its area (" << area << " m2) is " << (box > 0 ? 100 * area / box : 0)
      << " % of its bounding box (" << hi.x() - lo.x() << " x " << hi.y() - lo.y()
      << " m), less than " << 100 * kMinPolygonFill
      << " %: too thin to draw start points from; give a line instead, or a polygon with some "
         "width";
    return s.str();
  }
  return "";
}

std::optional<Eigen::Vector2d> PointOffTerrain(const Terrain& terrain,
                                               const ReleaseGeometry& release) {
  const auto off = [&](const Eigen::Vector2d& p) {
    double height_m;
    return !terrain.Height(p.x(), p.y(), &height_m);
  };
  const GridGeometry& grid = terrain.heights().grid;
  const bool polygon = release.kind == ReleaseGeometry::Kind::kPolygon;
  // Vertices first (they bound the walk below), then along the edges.
  for (const auto& ring : release.rings)
    for (const Eigen::Vector2d& v : ring)
      if (off(v)) return v;
  const double step = 0.25 * std::min(grid.dx_m, grid.dy_m);
  for (const auto& ring : release.rings) {
    const std::size_t n = ring.size();
    const std::size_t edges = n < 2 ? 0 : (polygon ? n : n - 1);
    for (std::size_t e = 0; e < edges; ++e) {
      const Eigen::Vector2d& a = ring[e];
      const Eigen::Vector2d& b = ring[(e + 1) % n];
      const long pieces = static_cast<long>(std::ceil((b - a).norm() / step));
      for (long q = 1; q < pieces; ++q) {
        const Eigen::Vector2d p = a + (double(q) / double(pieces)) * (b - a);
        if (off(p)) return p;
      }
    }
  }
  if (!polygon || release.rings.empty() || release.rings[0].empty()) return std::nullopt;
  // Inside: the cells with a nodata corner whose centre the polygon covers.
  Eigen::Vector2d lo = release.rings[0][0], hi = lo;
  for (const Eigen::Vector2d& v : release.rings[0]) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  const auto index = [](double f, int last) {
    return static_cast<int>(std::clamp(f, 0.0, double(last)));
  };
  const int i0 = index(std::floor((lo.x() - grid.x0_m) / grid.dx_m), grid.nx - 2);
  const int i1 = index(std::ceil((hi.x() - grid.x0_m) / grid.dx_m), grid.nx - 2);
  const int j0 = index(std::floor((lo.y() - grid.y0_m) / grid.dy_m), grid.ny - 2);
  const int j1 = index(std::ceil((hi.y() - grid.y0_m) / grid.dy_m), grid.ny - 2);
  const std::vector<double>& z = terrain.heights().z_m;
  for (int j = j0; j <= j1; ++j)
    for (int i = i0; i <= i1; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * grid.nx + i;
      if (!std::isnan(z[k]) && !std::isnan(z[k + 1]) && !std::isnan(z[k + grid.nx]) &&
          !std::isnan(z[k + grid.nx + 1]))
        continue;
      const Eigen::Vector2d centre(grid.x0_m + (i + 0.5) * grid.dx_m,
                                   grid.y0_m + (j + 0.5) * grid.dy_m);
      if (InsidePolygon(release.rings, centre)) return centre;
    }
  return std::nullopt;
}

std::uint64_t RockShapeSeed(std::uint64_t seed, long rock) {
  // SplitMix64 (Steele, Lea, Flood 2014) over a combination of the two.
  std::uint64_t z =
      seed * 0x9E3779B97F4A7C15ULL + static_cast<std::uint64_t>(rock) + 0x632BE59BD9B4E019ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

const char* ToString(VolumeDistribution::Kind kind) {
  switch (kind) {
    case VolumeDistribution::Kind::kFixed: return "fixed";
    case VolumeDistribution::Kind::kUniform: return "uniform";
    case VolumeDistribution::Kind::kLogNormal: return "lognormal";
    case VolumeDistribution::Kind::kPowerLaw: return "power_law";
  }
  return "?";
}

double VolumeDistribution::Quantile(double u) const {
  switch (kind) {
    case Kind::kFixed:
      break;
    case Kind::kUniform:
      return min_m3 + u * (max_m3 - min_m3);
    case Kind::kLogNormal: {
      // Inverse CDF of the normal restricted to [ln min, ln max].
      const boost::math::normal normal(std::log(median_m3), sigma);
      const double lo = min_m3 > 0 ? boost::math::cdf(normal, std::log(min_m3)) : 0.0;
      const double hi = std::isfinite(max_m3) ? boost::math::cdf(normal, std::log(max_m3)) : 1.0;
      const double p = std::clamp(lo + u * (hi - lo), 1e-300, 1.0 - 1e-16);
      return std::clamp(std::exp(boost::math::quantile(normal, p)), min_m3, max_m3);
    }
    case Kind::kPowerLaw: {
      // P(V >= v) = (v^-b - max^-b) / (min^-b - max^-b) on [min, max].
      const double a = std::pow(min_m3, -exponent), b = std::pow(max_m3, -exponent);
      return std::clamp(std::pow(a - u * (a - b), -1.0 / exponent), min_m3, max_m3);
    }
  }
  throw std::logic_error("VolumeDistribution::Quantile of a fixed volume");
}

bool VolumeDistribution::IsValid(std::string* why) const {
  std::ostringstream msg;
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  switch (kind) {
    case Kind::kFixed:
      return true;
    case Kind::kUniform:
    case Kind::kPowerLaw:
      if (!positive(min_m3)) msg << "min_m3 = " << min_m3 << " must be a number > 0";
      else if (!positive(max_m3) || !(max_m3 > min_m3))
        msg << "max_m3 = " << max_m3 << " must be a number > min_m3 = " << min_m3;
      else if (kind == Kind::kPowerLaw && !(exponent > 0 && exponent <= 10))
        msg << "exponent = " << exponent << " violates 0 < exponent <= 10";
      break;
    case Kind::kLogNormal:
      if (!positive(median_m3)) msg << "median_m3 = " << median_m3 << " must be a number > 0";
      else if (!(sigma > 0 && sigma <= 10)) msg << "sigma = " << sigma << " violates 0 < sigma <= 10";
      else if (!(min_m3 >= 0) || !(max_m3 > min_m3) || std::isnan(max_m3))
        msg << "min_m3 = " << min_m3 << ", max_m3 = " << max_m3
            << " must satisfy 0 <= min_m3 < max_m3";
      else if (!(median_m3 * std::exp(-8 * sigma) < max_m3 && median_m3 * std::exp(8 * sigma) > min_m3))
        msg << "min_m3 = " << min_m3 << " .. max_m3 = " << max_m3
            << " lies more than 8 sigma from median_m3 = " << median_m3;
      break;
  }
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

double RockVolume(const ReleaseSpec& spec, long rock) {
  RockRandom random(RockShapeSeed(spec.seed, rock), kRockVolumeStream);
  return spec.volume.Quantile(random.Uniform());
}

ReleasedRock Release(const Scene& scene, const ReleaseSpec& spec, long rock) {
  RockRandom random(spec.seed, static_cast<std::uint64_t>(rock));
  const int release = spec.ReleaseOf(rock);
  const ReleaseRun* run =
      spec.runs.empty() ? nullptr : &spec.runs[static_cast<std::size_t>(release)];

  // Shape: the rock's own, its run's block, or the scene's rock (not owned).
  const int block = run ? run->block : -1;
  ReleasedRock out;
  if (spec.shape_per_rock) {
    out.shape = std::make_shared<const RockShape>(
        spec.shape_per_rock(block >= 0 ? &spec.blocks[static_cast<std::size_t>(block)] : nullptr,
                            RockShapeSeed(spec.seed, rock)));
  } else if (block >= 0) {
    out.shape = spec.blocks[static_cast<std::size_t>(block)].shape;
  } else {
    out.shape = std::shared_ptr<const RockShape>(std::shared_ptr<const RockShape>(), &scene.rock);
  }
  if (spec.volume.kind != VolumeDistribution::Kind::kFixed)
    out.shape = std::make_shared<const RockShape>(
        ScaleRockShape(*out.shape, std::cbrt(RockVolume(spec, rock) / out.shape->volume_m3)));

  // Position: on the release geometry (where the terrain has a height, with clip_to_dem), or the
  // run's.
  Eigen::Vector2d xy;
  if (run) {
    xy = run->xy_m;
  } else {
    const ReleaseGeometry& g = spec.releases[static_cast<std::size_t>(release)];
    const auto keep = [&](const Eigen::Vector2d& p) {
      return !spec.clip_to_dem || OnTerrain(scene.terrain, p);
    };
    xy = g.rings[0][0];
    if (g.kind == ReleaseGeometry::Kind::kLine) xy = PointOnLine(g.rings[0], random, keep);
    if (g.kind == ReleaseGeometry::Kind::kPolygon) xy = PointInPolygon(g.rings, random, keep);
  }

  // The user's orientation rotates the shape as given; the state holds principal -> world.
  RockState& state = out.start;
  const std::optional<Eigen::Quaterniond>& fixed =
      run && run->orientation ? run->orientation : spec.orientation;
  const Eigen::Quaterniond user = fixed ? *fixed : random.Orientation();
  state.orientation = out.shape->PrincipalOrientation(user);

  // Height: the centre of mass height_m above the ground below it, or the lowest vertex height_m
  // above the ground below that vertex.
  TerrainSample ground;
  const double z = scene.terrain.Sample(xy.x(), xy.y(), &ground) ? ground.height_m : 0.0;
  const double height = run && run->height_m ? *run->height_m : spec.height_m;
  double z_m = z + height;
  if (spec.height_reference == ReleaseSpec::HeightReference::kLowestPoint) {
    const Eigen::Matrix3d rotation = state.orientation.toRotationMatrix();
    double highest_m = -std::numeric_limits<double>::infinity();  // of ground - vertex offset
    for (const Eigen::Vector3d& v : out.shape->vertices_m) {
      const Eigen::Vector3d offset = rotation * v;
      double ground_m;
      if (!scene.terrain.Height(xy.x() + offset.x(), xy.y() + offset.y(), &ground_m)) ground_m = z;
      highest_m = std::max(highest_m, ground_m - offset.z());
    }
    if (std::isfinite(highest_m)) z_m = highest_m + height;
  }
  state.position_m = Eigen::Vector3d(xy.x(), xy.y(), run && run->z_m ? *run->z_m : z_m);
  const Eigen::Vector3d& v = run ? run->velocity_m_s : spec.velocity_m_s;
  const Eigen::Vector3d& w = run ? run->angular_velocity_rad_s : spec.angular_velocity_rad_s;
  state.velocity_m_s = v;
  state.angular_velocity_rad_s = state.orientation.conjugate() * w;
  out.lift_m = RaiseAboveTerrain(scene, *out.shape, state);
  return out;
}

}  // namespace talus::ensemble
