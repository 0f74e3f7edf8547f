#include "solver/options.hpp"

#include <cmath>
#include <sstream>

namespace talus {

const char* ToString(ViscousReading reading) {
  switch (reading) {
    case ViscousReading::kCentreOfMass:
      return "centre_of_mass";
    case ViscousReading::kContactFriction:
      return "contact_friction";
  }
  return "unknown";
}

bool ParseViscousReading(std::string_view name, ViscousReading* reading) {
  for (ViscousReading r : {ViscousReading::kCentreOfMass, ViscousReading::kContactFriction}) {
    if (name == ToString(r)) {
      *reading = r;
      return true;
    }
  }
  return false;
}

const char* ToString(ContactSolveMethod method) {
  switch (method) {
    case ContactSolveMethod::kGaussSeidel:
      return "gauss_seidel";
    case ContactSolveMethod::kBlock:
      return "block";
  }
  return "unknown";
}

bool ParseContactSolveMethod(std::string_view name, ContactSolveMethod* method) {
  for (ContactSolveMethod m : {ContactSolveMethod::kGaussSeidel, ContactSolveMethod::kBlock}) {
    if (name == ToString(m)) {
      *method = m;
      return true;
    }
  }
  return false;
}

const char* ToString(PredictedLever lever) {
  switch (lever) {
    case PredictedLever::kMidpoint:
      return "midpoint";
    case PredictedLever::kTouch:
      return "touch";
  }
  return "unknown";
}

bool ParsePredictedLever(std::string_view name, PredictedLever* lever) {
  for (PredictedLever l : {PredictedLever::kMidpoint, PredictedLever::kTouch}) {
    if (name == ToString(l)) {
      *lever = l;
      return true;
    }
  }
  return false;
}

const char* ToString(SoilDragPoint point) {
  return point == SoilDragPoint::kSubmergedCentroid ? "submerged_centroid" : "centre_of_mass";
}

bool ParseSoilDragPoint(std::string_view name, SoilDragPoint* point) {
  for (SoilDragPoint p : {SoilDragPoint::kCentreOfMass, SoilDragPoint::kSubmergedCentroid}) {
    if (name == ToString(p)) {
      *point = p;
      return true;
    }
  }
  return false;
}

const char* ToString(SolverPreset preset) {
  switch (preset) {
    case SolverPreset::kFast:
      return "fast";
    case SolverPreset::kDefault:
      return "default";
    case SolverPreset::kAccurate:
      return "accurate";
  }
  return "unknown";
}

bool ParseSolverPreset(std::string_view name, SolverPreset* preset) {
  for (SolverPreset p : {SolverPreset::kFast, SolverPreset::kDefault, SolverPreset::kAccurate}) {
    if (name == ToString(p)) {
      *preset = p;
      return true;
    }
  }
  return false;
}

void ApplyPreset(SolverPreset preset, SolverOptions* options) {
  const SolverOptions defaults;
  options->dt_s = defaults.dt_s;
  options->tolerance_m_s = defaults.tolerance_m_s;
  options->max_iterations = defaults.max_iterations;
  switch (preset) {
    case SolverPreset::kFast:
      options->tolerance_m_s = 1e-2;
      break;
    case SolverPreset::kDefault:
      break;
    case SolverPreset::kAccurate:
      options->dt_s = 0.001;
      options->tolerance_m_s = 1e-7;
      options->max_iterations = 1000;
      break;
  }
}

bool SolverOptions::IsValid(std::string* why) const {
  std::ostringstream msg;
  auto check = [&](bool ok, const char* field, double value, const char* bound) {
    if (!ok && msg.str().empty()) msg << field << " = " << value << " violates " << bound;
  };
  check(dt_s > 0 && dt_s <= 0.1, "dt_s", dt_s, "0 < dt_s <= 0.1 s");
  check(max_time_s > 0 && std::isfinite(max_time_s), "max_time_s", max_time_s,
        "0 < max_time_s < inf");
  check(gravity_m_s2 >= 0 && std::isfinite(gravity_m_s2), "gravity_m_s2", gravity_m_s2,
        "gravity >= 0");
  check(normal_restitution >= 0 && normal_restitution <= 1, "normal_restitution",
        normal_restitution, "0 <= normal_restitution <= 1");
  check(tangential_restitution == normal_restitution, "tangential_restitution",
        tangential_restitution,
        "tangential_restitution == normal_restitution (Newton's impact law adds energy for unequal "
        "coefficients: Glocker 2013, Part I)");
  check(viscous == ViscousReading::kCentreOfMass || viscous == ViscousReading::kContactFriction,
        "viscous", static_cast<double>(viscous), "a ViscousReading value");
  check(tolerance_m_s > 0 && tolerance_m_s < 1, "tolerance_m_s", tolerance_m_s,
        "0 < tolerance_m_s < 1 m/s");
  check(max_iterations >= 1 && max_iterations <= 100000, "max_iterations", max_iterations,
        "1 <= max_iterations <= 100000");
  check(contact_solve == ContactSolveMethod::kGaussSeidel ||
            contact_solve == ContactSolveMethod::kBlock,
        "contact_solve", static_cast<double>(contact_solve), "a ContactSolveMethod value");
  check(prox_alpha > 0 && prox_alpha < 2, "prox_alpha", prox_alpha, "0 < prox_alpha < 2");
  check(penetration_tolerance > 0 && penetration_tolerance <= 0.5, "penetration_tolerance",
        penetration_tolerance, "0 < penetration_tolerance <= 0.5");
  check(predicted_lever == PredictedLever::kMidpoint || predicted_lever == PredictedLever::kTouch,
        "predicted_lever", static_cast<double>(predicted_lever), "a PredictedLever value");
  check(soil_drag == SoilDragPoint::kCentreOfMass ||
            soil_drag == SoilDragPoint::kSubmergedCentroid,
        "soil_drag", static_cast<double>(soil_drag), "a SoilDragPoint value");
  check(rest_speed_m_s >= 0 && std::isfinite(rest_speed_m_s), "rest_speed_m_s", rest_speed_m_s,
        "rest_speed_m_s >= 0");
  check(rest_angular_speed_rad_s >= 0 && std::isfinite(rest_angular_speed_rad_s),
        "rest_angular_speed_rad_s", rest_angular_speed_rad_s, "rest_angular_speed_rad_s >= 0");
  check(rest_hold_s >= 0 && std::isfinite(rest_hold_s), "rest_hold_s", rest_hold_s,
        "rest_hold_s >= 0");
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

}  // namespace talus
