#include "ensemble/release.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "solver/random.hpp"

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

// Even-odd rule over all rings, so that inner rings are holes.
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

Eigen::Vector2d PointInPolygon(const std::vector<std::vector<Eigen::Vector2d>>& rings,
                               RockRandom& random) {
  Eigen::Vector2d lo = rings[0][0], hi = rings[0][0];
  for (const Eigen::Vector2d& v : rings[0]) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  // Rejection sampling in the bounding box; IsValid ensures a positive area.
  for (int attempt = 0; attempt < 100000; ++attempt) {
    const double u = random.Uniform(), v = random.Uniform();
    const Eigen::Vector2d p(lo.x() + u * (hi.x() - lo.x()), lo.y() + v * (hi.y() - lo.y()));
    if (InsidePolygon(rings, p)) return p;
  }
  return rings[0][0];
}

}  // namespace

bool ReleaseSpec::IsValid(std::string* why) const {
  std::ostringstream s;
  if (releases.empty()) return Fail(why, "no release point, line or polygon");
  if (rocks_per_release < 1) {
    s << "rocks = " << rocks_per_release << " must be >= 1";
    return Fail(why, s.str());
  }
  if (rocks_per_release > kMaxTotalRocks / static_cast<long>(releases.size())) {
    s << "rocks = " << rocks_per_release << " per release x " << releases.size()
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
  for (std::size_t r = 0; r < releases.size(); ++r) {
    const ReleaseGeometry& g = releases[r];
    if (g.rings.empty() || g.rings[0].empty()) {
      s << "release " << r << " has no coordinates";
      return Fail(why, s.str());
    }
    for (const auto& ring : g.rings)
      for (const Eigen::Vector2d& v : ring)
        if (!v.allFinite()) {
          s << "release " << r << " has a non-finite coordinate";
          return Fail(why, s.str());
        }
    if (g.kind == ReleaseGeometry::Kind::kLine &&
        (g.rings[0].size() < 2 || LineLength(g.rings[0]) <= 0)) {
      s << "release " << r << ": a line needs at least 2 points and a positive length";
      return Fail(why, s.str());
    }
    if (g.kind == ReleaseGeometry::Kind::kPolygon &&
        (g.rings[0].size() < 3 || std::abs(RingArea(g.rings[0])) <= 0)) {
      s << "release " << r << ": a polygon needs at least 3 points and a positive area";
      return Fail(why, s.str());
    }
    if (g.kind == ReleaseGeometry::Kind::kPolygon) {
      // Holes (inner rings) must leave some area to sample from.
      double holes = 0;
      for (std::size_t k = 1; k < g.rings.size(); ++k) holes += std::abs(RingArea(g.rings[k]));
      if (holes >= std::abs(RingArea(g.rings[0]))) {
        s << "release " << r << ": the polygon's holes cover all of its area";
        return Fail(why, s.str());
      }
    }
  }
  return true;
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

RockState ReleaseState(const Scene& scene, const ReleaseSpec& spec, long rock) {
  RockRandom random(spec.seed, static_cast<std::uint64_t>(rock));
  const ReleaseGeometry& g = spec.releases[static_cast<std::size_t>(spec.ReleaseOf(rock))];
  Eigen::Vector2d xy = g.rings[0][0];
  if (g.kind == ReleaseGeometry::Kind::kLine) xy = PointOnLine(g.rings[0], random.Uniform());
  if (g.kind == ReleaseGeometry::Kind::kPolygon) xy = PointInPolygon(g.rings, random);

  RockState state;
  TerrainSample ground;
  const double z = scene.terrain.Sample(xy.x(), xy.y(), &ground) ? ground.height_m : 0.0;
  state.position_m = Eigen::Vector3d(xy.x(), xy.y(), z + spec.height_m);
  // The user's orientation rotates the shape as given; the state holds principal -> world.
  const Eigen::Quaterniond user = spec.orientation ? *spec.orientation : random.Orientation();
  state.orientation = scene.rock.PrincipalOrientation(user);
  state.velocity_m_s = spec.velocity_m_s;
  state.angular_velocity_rad_s = state.orientation.conjugate() * spec.angular_velocity_rad_s;
  return state;
}

}  // namespace talus::ensemble
