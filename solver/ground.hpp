#pragma once
// Ground categories: the five parameters of the seed paper's friction model per category.

#include <string>
#include <string_view>
#include <vector>

namespace talus {

// Parameters of one ground category (seed paper, Eqs. 1-3 and Table 1).
struct GroundParams {
  double mu_min = 0.35;    // friction coefficient at the start of a scar, dimensionless
  double mu_max = 2.0;     // limit friction coefficient of a long scar, dimensionless
  double beta_1_s = 150;   // scar decay rate in flight, 1/s
  double kappa_1_m = 2.0;  // scar hardening rate, 1/m
  double nu_1_s = 0.6;     // viscous ground term while in contact, 1/s (SolverOptions::viscous)

  // Drag layer (Leine et al. 2014, sec. 3.3; 2021, eq. 78), off unless drag_height_m > 0: while the
  // centre of mass is at most drag_height_m above the terrain over this category, the rock feels
  // the force -m c_t v and the torque -Theta c_r Omega (c_t, c_r below), in flight and in contact.
  // Low vegetation and forest in a first approximation; docs/model.md, "The drag layer".
  double drag_height_m = 0;           // layer thickness above the terrain, m, in [0, 100]
  double drag_translational_1_s = 0;  // c_t: v decays as exp(-c_t t), 1/s, in [0, 1000]
  double drag_rotational_1_s = 0;     // c_r: Omega decays as exp(-c_r t), 1/s, in [0, 1000]

  bool HasDragLayer() const {
    return drag_height_m > 0 && (drag_translational_1_s > 0 || drag_rotational_1_s > 0);
  }

  // Coulomb friction coefficient for scar length s >= 0:
  // mu(s) = mu_min + (2/pi) (mu_max - mu_min) atan(kappa s).
  double Friction(double scar_m) const;

  // False, with the field, value and violated bound in *why, when a value is non-physical.
  bool IsValid(std::string* why) const;
};

struct GroundCategory {
  std::string name;  // e.g. "medium_hard"
  int code = 0;      // value in a ground raster
  GroundParams params;
};

// The table of ground categories a scene uses. Indices are stable once built; calibration edits
// parameters in place between runs.
class GroundTable {
 public:
  // The eight categories of the seed paper's Table 1, codes 1-8.
  static GroundTable BuiltIn();

  // Adds a category, or replaces the one of the same name (its code may change).
  // Returns the category's index.
  int Set(const GroundCategory& category);

  int IndexOfCode(int code) const;               // -1 when no category has this code
  int IndexOfName(std::string_view name) const;  // -1 when unknown

  int size() const { return static_cast<int>(categories_.size()); }
  const GroundCategory& category(int index) const { return categories_[index]; }
  const GroundParams& params(int index) const { return categories_[index].params; }
  GroundParams& mutable_params(int index) { return categories_[index].params; }

  // True when some category has a drag layer (the step then looks up the layer under the rock).
  bool AnyDragLayer() const;

  // Checks every category and that names and codes are unique.
  bool IsValid(std::string* why) const;

 private:
  std::vector<GroundCategory> categories_;
};

}  // namespace talus
