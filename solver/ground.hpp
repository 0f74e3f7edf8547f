#pragma once
// Ground categories: the five parameters of the seed paper's friction model per category, the
// optional drag layer and the optional scarring soil of Lu et al. 2019.

#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "solver/option_table.hpp"

namespace talus {

// What lies under the DEM surface of a category (docs/model.md, "The scarring soil").
enum class GroundModel {
  // The seed's hard contact at the DEM surface (Signorini, Coulomb with mu(s)).
  kHard,
  // Lu et al. 2019: a compactable scarring layer between the DEM surface and a hard rebound plane
  // at the penetration depth d_max (eq. 11) below it; inside the layer a velocity-squared drag
  // (eqs. 9, 12) on the frontal area of the rock's part below the surface; on the plane the hard
  // contact with mu(s) (eqs. 13, 14).
  kLu2019,
};
extern const EnumNames kGroundModelNames;  // "hard", "lu2019"
const char* ToString(GroundModel model);
bool ParseGroundModel(std::string_view name, GroundModel* model);

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

  // Scarring soil (Lu et al. 2019), used when model == kLu2019. Defaults: the paper's
  // whole-trajectory soil (M_E 15 MN/m^2, C_s 1.5) with its fixed C_f and rho.
  GroundModel model = GroundModel::kHard;
  double soil_strength_mn_m2 = 15;   // M_E, MN/m^2 (eq. 11 takes kN/m^2: 15 enters as 15 000)
  double compaction_drag = 1.5;      // C_s, dimensionless (eq. 12)
  double fluid_drag = 1.0;           // C_f, dimensionless (eq. 12)
  double soil_density_kg_m3 = 1700;  // rho_Sigma, kg/m^3 (eq. 9)

  bool HasDragLayer() const {
    return drag_height_m > 0 && (drag_translational_1_s > 0 || drag_rotational_1_s > 0);
  }
  bool IsSoil() const { return model == GroundModel::kLu2019; }

  // Coulomb friction coefficient for scar length s >= 0:
  // mu(s) = mu_min + (2/pi) (mu_max - mu_min) atan(kappa s).
  double Friction(double scar_m) const;

  // Lu et al. 2019, eq. 11: the depth (m) of the rebound plane below the surface for a rock of
  // mass_kg that meets the soil with vertical speed |V_perp| (m/s):
  // d_max = 0.1 M^(1/3) M_E^(-0.4) |V_perp|^0.8, M_E in kN/m^2.
  double PenetrationDepth(double mass_kg, double vertical_speed_m_s) const;
  // C_d = C_f + C_s (eq. 12) times rho_Sigma / 2: the drag force is this times A |v|^2 (eq. 9).
  double DragFactor_kg_m3() const {
    return 0.5 * (fluid_drag + compaction_drag) * soil_density_kg_m3;
  }

  // False, with the field, value and violated bound in *why, when a value is non-physical.
  bool IsValid(std::string* why) const;
};

// One number of GroundParams as scene files, summary.json, calibration and docs name it: every
// list of ground fields reads kGroundFields, so that a new field is one row here.
struct GroundFieldInfo {
  enum class Group {
    kFriction,   // the seed's five parameters; always written
    kDragLayer,  // written for a category with a drag layer
    kSoil,       // written for a category with model = "lu2019"
  };
  const char* key;  // scene key in [ground.<name>], e.g. "mu_min"
  double GroundParams::*member;
  const char* unit;  // "1" for dimensionless
  Bounds valid;      // GroundParams::IsValid
  Group group;
  bool calibrated;  // calibration may free it (calibration::GroundField has the same order)
  bool log_scale;   // calibration's default transform
  const char* doc;
};
extern const std::array<GroundFieldInfo, 12> kGroundFields;
// nullptr when `key` is no field's key.
const GroundFieldInfo* FindGroundField(std::string_view key);
// True when `field` is written for a category with these parameters (its group is present).
bool GroundFieldApplies(const GroundFieldInfo& field, const GroundParams& params);

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
  // Their names, in code order.
  static const std::array<const char*, 8>& BuiltInNames();

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
  // True when some category has the scarring soil (contact detection then looks for it).
  bool AnySoil() const;

  // Checks every category and that names and codes are unique.
  bool IsValid(std::string* why) const;

 private:
  std::vector<GroundCategory> categories_;
};

}  // namespace talus
