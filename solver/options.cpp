#include "solver/options.hpp"

#include <sstream>
#include <type_traits>

namespace talus {

namespace {

constexpr std::array<const char*, 2> kViscousReadings = {"centre_of_mass", "contact_friction"};
constexpr std::array<const char*, 3> kContactSolveMethods = {"gauss_seidel", "block",
                                                             "block_on_stall"};
constexpr std::array<const char*, 2> kPredictedLevers = {"midpoint", "touch"};
constexpr std::array<const char*, 2> kContactHolds = {"midpoint", "held"};
constexpr std::array<const char*, 2> kSubstepImpacts = {"fast", "all"};
constexpr std::array<const char*, 2> kSoilDragPoints = {"centre_of_mass", "submerged_centroid"};
constexpr std::array<const char*, 3> kSolverPresets = {"fast", "default", "accurate"};

}  // namespace

constinit const EnumNames kViscousReadingNames{"reading", kViscousReadings};
constinit const EnumNames kContactSolveMethodNames{"method", kContactSolveMethods};
constinit const EnumNames kPredictedLeverNames{"lever", kPredictedLevers};
constinit const EnumNames kContactHoldNames{"contact hold", kContactHolds};
constinit const EnumNames kSubstepImpactsNames{"impacts", kSubstepImpacts};
constinit const EnumNames kSoilDragPointNames{"drag point", kSoilDragPoints};
constinit const EnumNames kSolverPresetNames{"preset", kSolverPresets};

const char* ToString(ViscousReading reading) { return kViscousReadingNames.NameOf(reading); }
bool ParseViscousReading(std::string_view name, ViscousReading* reading) {
  return kViscousReadingNames.Parse(name, reading);
}

const char* ToString(ContactSolveMethod method) { return kContactSolveMethodNames.NameOf(method); }
bool ParseContactSolveMethod(std::string_view name, ContactSolveMethod* method) {
  return kContactSolveMethodNames.Parse(name, method);
}

const char* ToString(PredictedLever lever) { return kPredictedLeverNames.NameOf(lever); }
bool ParsePredictedLever(std::string_view name, PredictedLever* lever) {
  return kPredictedLeverNames.Parse(name, lever);
}

const char* ToString(ContactHold hold) { return kContactHoldNames.NameOf(hold); }
bool ParseContactHold(std::string_view name, ContactHold* hold) {
  return kContactHoldNames.Parse(name, hold);
}

const char* ToString(SubstepImpacts impacts) { return kSubstepImpactsNames.NameOf(impacts); }
bool ParseSubstepImpacts(std::string_view name, SubstepImpacts* impacts) {
  return kSubstepImpactsNames.Parse(name, impacts);
}

const char* ToString(SoilDragPoint point) { return kSoilDragPointNames.NameOf(point); }
bool ParseSoilDragPoint(std::string_view name, SoilDragPoint* point) {
  return kSoilDragPointNames.Parse(name, point);
}

const char* ToString(SolverPreset preset) { return kSolverPresetNames.NameOf(preset); }
bool ParseSolverPreset(std::string_view name, SolverPreset* preset) {
  return kSolverPresetNames.Parse(name, preset);
}

namespace {

using O = SolverOptions;
using Type = SolverOptionInfo::Type;

template <auto kMember>
constexpr SolverOptionInfo::Member MemberOf() {
  return {[](const SolverOptions& o) { return static_cast<double>(o.*kMember); },
          [](SolverOptions& o, double v) {
            using T = std::remove_cvref_t<decltype(o.*kMember)>;
            if constexpr (std::is_enum_v<T>) {
              o.*kMember = static_cast<T>(static_cast<int>(v));
            } else {
              o.*kMember = static_cast<T>(v);
            }
          }};
}

// A choice's valid values: the numbers of its enumerators.
template <std::size_t N>
constexpr Bounds Choices(const std::array<const char*, N>& /*names*/) {
  return Bounds::Between(0, static_cast<double>(N) - 1);
}

}  // namespace

// In the order of summary.json's "solver".
constinit const std::array<SolverOptionInfo, 19> kSolverOptions = {{
    {.key = "dt_s",
     .type = Type::kNumber,
     .member = MemberOf<&O::dt_s>(),
     .unit = "s",
     .valid = Bounds::AboveAtMost(0, 0.1),
     .preset_knob = true,
     .doc = "time step"},
    {.key = "max_time_s",
     .type = Type::kNumber,
     .member = MemberOf<&O::max_time_s>(),
     .unit = "s",
     .valid = Bounds::Above(0),
     .doc = "a rock still moving then ends as max_time"},
    {.key = "gravity_m_s2",
     .type = Type::kNumber,
     .member = MemberOf<&O::gravity_m_s2>(),
     .unit = "m/s2",
     .valid = Bounds::AtLeast(0),
     .plausible_lower = 0.1,
     .plausible_upper = 100,
     .doc = "along -z"},
    {.key = "normal_restitution",
     .type = Type::kNumber,
     .member = MemberOf<&O::normal_restitution>(),
     .unit = "1",
     .valid = Bounds::Between(0, 1),
     .doc = "epsilon of Newton's impact law; the model is fully plastic (0)"},
    {.key = "tangential_restitution",
     .type = Type::kNumber,
     .member = MemberOf<&O::tangential_restitution>(),
     .unit = "1",
     .valid = Bounds::Between(0, 1),
     .doc = "must equal normal_restitution, which it follows unless given (one coefficient)"},
    {.key = "viscous",
     .type = Type::kChoice,
     .member = MemberOf<&O::viscous>(),
     .unit = "1",
     .valid = Choices(kViscousReadings),
     .choices = &kViscousReadingNames,
     .doc = "how the ground's nu acts (below)"},
    {.key = "contact_solve",
     .type = Type::kChoice,
     .member = MemberOf<&O::contact_solve>(),
     .unit = "1",
     .valid = Choices(kContactSolveMethods),
     .choices = &kContactSolveMethodNames,
     .doc = "how a step with two contacts is solved (below)"},
    {.key = "tolerance_m_s",
     .type = Type::kNumber,
     .member = MemberOf<&O::tolerance_m_s>(),
     .unit = "m/s",
     .valid = Bounds::Inside(0, 1),
     .preset_knob = true,
     .doc = "the contact solve stops when no sweep changes a contact velocity by more"},
    {.key = "max_iterations",
     .type = Type::kInteger,
     .member = MemberOf<&O::max_iterations>(),
     .unit = "1",
     .valid = Bounds::Between(1, 100000),
     .preset_knob = true,
     .doc = "contact solve sweeps at most"},
    {.key = "prox_alpha",
     .type = Type::kNumber,
     .member = MemberOf<&O::prox_alpha>(),
     .unit = "1",
     .valid = Bounds::Inside(0, 2),
     .doc = "step length of the contact solve's prox iteration"},
    // A fraction of the rock's thickness (its smallest extent along the principal axes).
    {.key = "penetration_tolerance",
     .type = Type::kNumber,
     .member = MemberOf<&O::penetration_tolerance>(),
     .unit = "1",
     .valid = Bounds::AboveAtMost(0, 0.5),
     .doc = "a predicted contact is stopped at this fraction of the rock's thickness"},
    {.key = "predicted_lever",
     .type = Type::kChoice,
     .member = MemberOf<&O::predicted_lever>(),
     .unit = "1",
     .valid = Choices(kPredictedLevers),
     .choices = &kPredictedLeverNames,
     .doc = "where a predicted contact's percussion acts (below)"},
    {.key = "contact_hold",
     .type = Type::kChoice,
     .member = MemberOf<&O::contact_hold>(),
     .unit = "1",
     .valid = Choices(kContactHolds),
     .choices = &kContactHoldNames,
     .doc = "whether a contact of the step before that gravity brings back is held (below)"},
    {.key = "impact_substeps",
     .type = Type::kInteger,
     .member = MemberOf<&O::impact_substeps>(),
     .unit = "1",
     .valid = Bounds::Between(1, 64),
     .doc = "a step with an impact is taken as this many sub-steps; 1: never (below)"},
    {.key = "substep_impacts",
     .type = Type::kChoice,
     .member = MemberOf<&O::substep_impacts>(),
     .unit = "1",
     .valid = Choices(kSubstepImpacts),
     .choices = &kSubstepImpactsNames,
     .doc = "which steps impact_substeps splits: fast impacts, or every new contact (below)"},
    {.key = "soil_drag",
     .type = Type::kChoice,
     .member = MemberOf<&O::soil_drag>(),
     .unit = "1",
     .valid = Choices(kSoilDragPoints),
     .choices = &kSoilDragPointNames,
     .doc = "where the scar drag of a soil category acts (below)"},
    {.key = "rest_speed_m_s",
     .type = Type::kNumber,
     .member = MemberOf<&O::rest_speed_m_s>(),
     .unit = "m/s",
     .valid = Bounds::AtLeast(0),
     .doc = "at rest: slower than this, in contact, for rest_hold_s"},
    {.key = "rest_angular_speed_rad_s",
     .type = Type::kNumber,
     .member = MemberOf<&O::rest_angular_speed_rad_s>(),
     .unit = "rad/s",
     .valid = Bounds::AtLeast(0),
     .doc = "at rest: turning slower than this, in contact, for rest_hold_s"},
    {.key = "rest_hold_s",
     .type = Type::kNumber,
     .member = MemberOf<&O::rest_hold_s>(),
     .unit = "s",
     .valid = Bounds::AtLeast(0),
     .doc = "how long a rock must be slow to be at rest"},
}};

const SolverOptionInfo* FindSolverOption(std::string_view key) {
  for (const SolverOptionInfo& f : kSolverOptions)
    if (key == f.key) return &f;
  return nullptr;
}

void ApplyPreset(SolverPreset preset, SolverOptions* options) {
  const SolverOptions defaults;
  for (const SolverOptionInfo& f : kSolverOptions)
    if (f.preset_knob) f.member.set(*options, f.member.get(defaults));
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
  for (const SolverOptionInfo& f : kSolverOptions) {
    const double v = f.member.get(*this);
    if (f.valid.Contains(v)) continue;
    if (why) {
      std::ostringstream msg;
      msg << f.key << " = " << v;
      if (f.choices) {
        msg << " is not one of " << f.choices->List();
      } else {
        msg << " violates " << f.valid.Describe(f.key);
        if (std::string_view(f.unit) != "1") msg << " " << f.unit;
      }
      *why = msg.str();
    }
    return false;
  }
  // Across fields: Newton's law takes one coefficient (SolverOptions::normal_restitution).
  if (tangential_restitution != normal_restitution) {
    if (why) {
      std::ostringstream msg;
      msg << "tangential_restitution = " << tangential_restitution
          << " violates tangential_restitution == normal_restitution (Newton's impact law adds "
             "energy for unequal coefficients: Glocker 2013, Part I)";
      *why = msg.str();
    }
    return false;
  }
  return true;
}

}  // namespace talus
