#include "fieldobs/single_impacts.hpp"

#include <cassert>
#include <cmath>
#include <set>
#include <sstream>

#include "common/error.hpp"

namespace talus::fieldobs {
namespace {

constexpr double kPi = 3.14159265358979323846;
// How far the total speed and angle may disagree with the components they repeat.
constexpr double kSpeedAgreement = 0.01, kAngleAgreement_deg = 0.5;

std::string Fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

double Angle_deg(const CsvTable& t, int row, const std::string& column) {
  const double a = t.Number(row, column);
  if (!(a > 0 && a <= 90))
    throw InputError(t.Where(row, column) + ": impact angle " + t.Text(row, column) +
                     " deg is outside (0, 90]: the angle between the incoming velocity and the "
                     "plane, 90 for a vertical impact");
  return a;
}

// Components from the total speed and angle, or checked against them when both are given.
void ReadVelocity(const CsvTable& t, const SingleImpactColumns& c, int row, bool components,
                  bool total, IncomingImpact& impact) {
  if (components) {
    impact.normal_speed_m_s = t.NonNegativeNumber(row, c.normal_speed);
    impact.tangent_speed_m_s = t.NonNegativeNumber(row, c.tangent_speed);
  }
  if (!total) return;
  const double speed = t.NonNegativeNumber(row, c.total_speed);
  const double angle = Angle_deg(t, row, c.angle);
  if (!components) {
    impact.normal_speed_m_s = speed * std::sin(angle * kPi / 180);
    impact.tangent_speed_m_s = speed * std::cos(angle * kPi / 180);
    return;
  }
  const double from_components = std::hypot(impact.normal_speed_m_s, impact.tangent_speed_m_s);
  const double angle_from_components =
      std::atan2(impact.normal_speed_m_s, impact.tangent_speed_m_s) * 180 / kPi;
  if (std::abs(from_components - speed) > kSpeedAgreement * speed)
    throw InputError(t.Where(row, c.total_speed) + ": " + t.Text(row, c.total_speed) +
                     " m/s disagrees with the components " + c.normal_speed + " and " +
                     c.tangent_speed + " (" + Fmt(from_components) + " m/s, more than 1 %)");
  if (std::abs(angle_from_components - angle) > kAngleAgreement_deg)
    throw InputError(t.Where(row, c.angle) + ": " + t.Text(row, c.angle) +
                     " deg disagrees with the components " + c.normal_speed + " and " +
                     c.tangent_speed + " (" + Fmt(angle_from_components) + " deg, more than " +
                     Fmt(kAngleAgreement_deg) + " deg)");
}

}  // namespace

std::vector<IncomingImpact> ReadIncomingImpacts(const CsvTable& t, const SingleImpactColumns& c) {
  t.Require({c.id});
  const bool components = t.Has(c.normal_speed) || t.Has(c.tangent_speed);
  const bool total = t.Has(c.total_speed) || t.Has(c.angle);
  if (!components && !total)
    throw InputError(t.path() + ": no incoming velocity: give the columns " + c.normal_speed +
                     " and " + c.tangent_speed + ", or " + c.total_speed + " and " + c.angle);
  if (components) t.Require({c.normal_speed, c.tangent_speed});
  if (total) t.Require({c.total_speed, c.angle});
  if (!c.angular_speed.empty()) t.Require({c.angular_speed});
  if (t.rows() == 0) throw InputError(t.path() + ": no impact (the table has a header only)");
  std::vector<IncomingImpact> out;
  std::set<std::string> ids;
  for (int row = 0; row < t.rows(); ++row) {
    IncomingImpact impact;
    impact.id = t.Text(row, c.id);
    if (impact.id.empty()) throw InputError(t.Where(row, c.id) + ": empty impact id");
    if (!ids.insert(impact.id).second)
      throw InputError(t.Where(row, c.id) + ": impact '" + impact.id + "' appears twice");
    impact.where = t.path() + ":" + std::to_string(t.line(row));
    ReadVelocity(t, c, row, components, total, impact);
    if (!(impact.normal_speed_m_s > 0))
      throw InputError(t.Where(row, components ? c.normal_speed : c.angle) +
                       ": no normal component: a single impact needs a velocity towards the plane");
    if (!c.angular_speed.empty()) impact.angular_speed_rad_s = t.Number(row, c.angular_speed);
    out.push_back(impact);
  }
  return out;
}

Eigen::Vector3d DownslopeDirection(const Eigen::Vector3d& normal) {
  const Eigen::Vector3d down = -Eigen::Vector3d::UnitZ() + normal.z() * normal;
  return down.norm() > 1e-12 ? Eigen::Vector3d(down.normalized()) : Eigen::Vector3d::UnitX();
}

ensemble::ReleaseRun SingleImpactRun(const IncomingImpact& impact, const Terrain& terrain,
                                     const Eigen::Vector2d& xy_m, double clearance_m, int block) {
  TerrainSample ground;
  [[maybe_unused]] const bool on = terrain.Sample(xy_m.x(), xy_m.y(), &ground);
  assert(on && "SingleImpactRun needs a point where the terrain has a height");
  const Eigen::Vector3d n = ground.normal.normalized();
  const Eigen::Vector3d d = DownslopeDirection(n);
  ensemble::ReleaseRun run;
  run.id = impact.id;
  run.xy_m = xy_m;
  run.height_m = clearance_m;
  run.velocity_m_s = impact.tangent_speed_m_s * d - impact.normal_speed_m_s * n;
  run.angular_velocity_rad_s = impact.angular_speed_rad_s * n.cross(d);
  run.block = block;
  return run;
}

void ReadSingleImpactOutcomes(const CsvTable& t, const SingleImpactColumns& c,
                              ObservationSet& out) {
  t.Require({c.id});
  if (!t.Has(c.energy_ratio) && !t.Has(c.speed_out))
    throw InputError(t.path() + ": no observed outcome: give the column " + c.energy_ratio +
                     " (translational energy after / before) or " + c.speed_out +
                     " (speed after the impact, m/s)");
  for (int row = 0; row < t.rows(); ++row) {
    const std::string run = t.Text(row, c.id);
    if (run.empty()) throw InputError(t.Where(row, c.id) + ": empty impact id");
    const std::string where = t.path() + ":" + std::to_string(t.line(row));
    if (!t.Empty(row, c.energy_ratio))
      out.scalars.push_back(
          {Quantity::kImpactEnergyRatio, run, t.NonNegativeNumber(row, c.energy_ratio), where});
    if (!t.Empty(row, c.speed_out))
      out.scalars.push_back(
          {Quantity::kImpactSpeedOut, run, t.NonNegativeNumber(row, c.speed_out), where});
  }
  if (!t.Has(c.scar_depth)) return;
  for (int row = 0; row < t.rows(); ++row)
    if (!t.Empty(row, c.scar_depth))
      out.scalars.push_back({Quantity::kImpactScarDepth, t.Text(row, c.id),
                             t.NonNegativeNumber(row, c.scar_depth),
                             t.path() + ":" + std::to_string(t.line(row))});
}

}  // namespace talus::fieldobs
