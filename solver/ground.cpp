#include "solver/ground.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

namespace talus {

double GroundParams::Friction(double scar_m) const {
  return mu_min + (2.0 / std::numbers::pi) * (mu_max - mu_min) * std::atan(kappa_1_m * scar_m);
}

namespace {
bool Check(bool ok, std::string* why, const char* field, double value, const char* bound) {
  if (!ok && why) {
    std::ostringstream msg;
    msg << field << " = " << value << " violates " << bound;
    *why = msg.str();
  }
  return ok;
}
}  // namespace

bool GroundParams::IsValid(std::string* why) const {
  return Check(std::isfinite(mu_min) && mu_min >= 0, why, "mu_min", mu_min, "0 <= mu_min") &&
         Check(std::isfinite(mu_max) && mu_max >= mu_min, why, "mu_max", mu_max,
               "mu_min <= mu_max < infinity") &&
         Check(std::isfinite(beta_1_s) && beta_1_s >= 0, why, "beta", beta_1_s,
               "beta >= 0 (1/s)") &&
         Check(std::isfinite(kappa_1_m) && kappa_1_m >= 0, why, "kappa", kappa_1_m,
               "kappa >= 0 (1/m)") &&
         Check(std::isfinite(nu_1_s) && nu_1_s >= 0, why, "nu", nu_1_s, "nu >= 0 (1/s)") &&
         Check(std::isfinite(drag_height_m) && drag_height_m >= 0 && drag_height_m <= 100, why,
               "drag_height_m", drag_height_m, "0 <= drag_height_m <= 100 (m)") &&
         Check(std::isfinite(drag_translational_1_s) && drag_translational_1_s >= 0 &&
                   drag_translational_1_s <= 1000,
               why, "drag_translational", drag_translational_1_s,
               "0 <= drag_translational <= 1000 (1/s)") &&
         Check(std::isfinite(drag_rotational_1_s) && drag_rotational_1_s >= 0 &&
                   drag_rotational_1_s <= 1000,
               why, "drag_rotational", drag_rotational_1_s, "0 <= drag_rotational <= 1000 (1/s)");
}

bool GroundTable::AnyDragLayer() const {
  for (const GroundCategory& c : categories_)
    if (c.params.HasDragLayer()) return true;
  return false;
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
