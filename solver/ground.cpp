#include "solver/ground.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

namespace talus {

double GroundParams::Friction(double scar_m) const {
  return mu_min + (2.0 / std::numbers::pi) * (mu_max - mu_min) * std::atan(kappa_1_m * scar_m);
}

double GroundParams::PenetrationDepth(double mass_kg, double vertical_speed_m_s) const {
  const double strength_kn_m2 = 1000.0 * soil_strength_mn_m2;
  return 0.1 * std::cbrt(mass_kg) * std::pow(strength_kn_m2, -0.4) *
         std::pow(std::abs(vertical_speed_m_s), 0.8);
}

namespace {
constexpr std::array<const char*, 2> kGroundModels = {"hard", "lu2019"};
using Group = GroundFieldInfo::Group;
}  // namespace

constinit const EnumNames kGroundModelNames{"ground model", kGroundModels};

const char* ToString(GroundModel model) { return kGroundModelNames.NameOf(model); }

bool ParseGroundModel(std::string_view name, GroundModel* model) {
  return kGroundModelNames.Parse(name, model);
}

// The order of the calibrated fields is calibration::GroundField's.
const std::array<GroundFieldInfo, 12> kGroundFields = {{
    {"mu_min", &GroundParams::mu_min, "1", Bounds::Between(0, 10), Group::kFriction, true, false,
     "friction coefficient at the start of a scar"},
    {"mu_max", &GroundParams::mu_max, "1", Bounds::Between(0, 10), Group::kFriction, true, false,
     "limit friction coefficient of a long scar (>= mu_min)"},
    {"beta", &GroundParams::beta_1_s, "1/s", Bounds::Between(0, 1e5), Group::kFriction, true, true,
     "scar decay rate in flight"},
    {"kappa", &GroundParams::kappa_1_m, "1/m", Bounds::Between(0, 1e4), Group::kFriction, true,
     true, "scar hardening rate"},
    {"nu", &GroundParams::nu_1_s, "1/s", Bounds::Between(0, 1e4), Group::kFriction, true, true,
     "viscous ground term while in contact ([solver] viscous)"},
    {"soil_strength", &GroundParams::soil_strength_mn_m2, "MN/m^2", Bounds::Between(0.1, 1000),
     Group::kSoil, true, true,
     "M_E, soil strength of eq. 11 (Lu et al. 2019; the formula takes kN/m^2)"},
    {"compaction_drag", &GroundParams::compaction_drag, "1", Bounds::Between(0, 100), Group::kSoil,
     true, false, "C_s, compaction part of the scar drag coefficient (eq. 12)"},
    {"fluid_drag", &GroundParams::fluid_drag, "1", Bounds::Between(0, 100), Group::kSoil, false,
     false, "C_f, fluid part of the scar drag coefficient (eq. 12)"},
    {"soil_density", &GroundParams::soil_density_kg_m3, "kg/m^3", Bounds::Between(100, 3000),
     Group::kSoil, false, false, "rho_Sigma, density of the scarring layer (eq. 9)"},
    {"drag_height_m", &GroundParams::drag_height_m, "m", Bounds::Between(0, 100), Group::kDragLayer,
     false, false, "drag layer thickness above the terrain"},
    {"drag_translational", &GroundParams::drag_translational_1_s, "1/s", Bounds::Between(0, 1000),
     Group::kDragLayer, false, false, "drag layer: v decays as exp(-c_t t)"},
    {"drag_rotational", &GroundParams::drag_rotational_1_s, "1/s", Bounds::Between(0, 1000),
     Group::kDragLayer, false, false, "drag layer: Omega decays as exp(-c_r t)"},
}};

const GroundFieldInfo* FindGroundField(std::string_view key) {
  for (const GroundFieldInfo& f : kGroundFields)
    if (key == f.key) return &f;
  return nullptr;
}

bool GroundFieldApplies(const GroundFieldInfo& field, const GroundParams& params) {
  switch (field.group) {
    case Group::kFriction:
      return true;
    case Group::kDragLayer:
      return params.HasDragLayer();
    case Group::kSoil:
      return params.IsSoil();
  }
  return true;
}

bool GroundParams::IsValid(std::string* why) const {
  for (const GroundFieldInfo& f : kGroundFields) {
    const double v = this->*f.member;
    if (f.valid.Contains(v)) continue;
    if (why) {
      std::ostringstream msg;
      msg << f.key << " = " << v << " violates " << f.valid.Describe(f.key);
      if (std::string_view(f.unit) != "1") msg << " (" << f.unit << ")";
      *why = msg.str();
    }
    return false;
  }
  if (!(mu_max >= mu_min)) {
    if (why) {
      std::ostringstream msg;
      msg << "mu_max = " << mu_max << " violates mu_min <= mu_max < infinity";
      *why = msg.str();
    }
    return false;
  }
  return true;
}

bool GroundTable::AnyDragLayer() const {
  for (const GroundCategory& c : categories_)
    if (c.params.HasDragLayer()) return true;
  return false;
}

bool GroundTable::AnySoil() const {
  for (const GroundCategory& c : categories_)
    if (c.params.IsSoil()) return true;
  return false;
}

const std::array<const char*, 8>& GroundTable::BuiltInNames() {
  static const std::array<const char*, 8> names = {"extra_soft",  "soft", "medium_soft", "medium",
                                                   "medium_hard", "hard", "extra_hard",  "snow"};
  return names;
}

GroundTable GroundTable::BuiltIn() {
  // Seed paper, Table 1 (RAMMS::ROCKFALL ground categories).
  GroundTable table;
  table.Set({"extra_soft", 1, {0.20, 2.0, 50, 1.0, 0.9}});
  table.Set({"soft", 2, {0.25, 2.0, 100, 1.25, 0.8}});
  table.Set({"medium_soft", 3, {0.30, 2.0, 125, 1.5, 0.7}});
  table.Set({"medium", 4, {0.35, 2.0, 150, 2.0, 0.6}});
  table.Set({"medium_hard", 5, {0.40, 2.0, 175, 2.5, 0.5}});
  table.Set({"hard", 6, {0.55, 2.0, 185, 3.0, 0.4}});
  table.Set({"extra_hard", 7, {0.80, 2.0, 200, 4.0, 0.3}});
  table.Set({"snow", 8, {0.10, 0.35, 150, 2.0, 0.7}});
  return table;
}

int GroundTable::Set(const GroundCategory& category) {
  int index = IndexOfName(category.name);
  if (index >= 0) {
    categories_[index] = category;
    return index;
  }
  categories_.push_back(category);
  return size() - 1;
}

int GroundTable::IndexOfCode(int code) const {
  for (int i = 0; i < size(); ++i)
    if (categories_[i].code == code) return i;
  return -1;
}

int GroundTable::IndexOfName(std::string_view name) const {
  for (int i = 0; i < size(); ++i)
    if (categories_[i].name == name) return i;
  return -1;
}

bool GroundTable::IsValid(std::string* why) const {
  for (int i = 0; i < size(); ++i) {
    const GroundCategory& c = categories_[i];
    std::string reason;
    if (!c.params.IsValid(&reason)) {
      if (why) *why = "ground category '" + c.name + "': " + reason;
      return false;
    }
    for (int j = 0; j < i; ++j) {
      if (categories_[j].code == c.code) {
        if (why)
          *why = "ground categories '" + categories_[j].name + "' and '" + c.name +
                 "' share code " + std::to_string(c.code);
        return false;
      }
    }
  }
  return true;
}

}  // namespace talus
