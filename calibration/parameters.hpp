#pragma once
// The free parameters of a calibration and the map from the optimiser's vector to a ground table.
//
// Coordinates. The optimiser works in the unit cube: coordinate u in [0, 1] of a parameter with
// bounds [lower, upper] is
//   value = lower + u (upper - lower)                      (linear), or
//   value = exp(log lower + u (log upper - log lower))     (log transform),
// so that every coordinate is dimensionless, bounded by [0, 1], and steps, tolerances, designs
// (Sobol, Latin hypercube) and the prior are all stated in the same "fraction of the range".
// Several parameters sharing a tie name share one coordinate (e.g. one mu_max for all categories).

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "solver/ground.hpp"

namespace talus::calibration {

// The fields of a ground category that a calibration may free: the seed's five and the scarring
// soil's two (a category with model = "lu2019"). In the order of kGroundFields
// (solver/ground.hpp), whose rows give their names, units and default transforms.
enum class GroundField {
  kMuMin,
  kMuMax,
  kBeta,
  kKappa,
  kNu,
  kSoilStrength,
  kCompactionDrag
};
const GroundFieldInfo& InfoOf(GroundField field);
const char* ToString(GroundField field);  // "mu_min", ..., "soil_strength", "compaction_drag"
const char* UnitOf(GroundField field);    // "1", "1", "1/s", "1/m", "1/s", "MN/m^2", "1"
bool ParseGroundField(const std::string& name, GroundField* field);
double& FieldOf(GroundParams& params, GroundField field);
double FieldOf(const GroundParams& params, GroundField field);

// One free parameter: a field of one ground category, its physical bounds and its transform.
struct ParameterSpec {
  std::string category;  // a category of the scene's ground table, e.g. "medium"
  GroundField field = GroundField::kMuMin;
  double lower = 0;  // in the field's unit; > 0
  double upper = 0;  // > lower; mu <= kMaxFriction
  // Log transform of the coordinate; nullopt: on for beta, kappa, nu and soil_strength, off for
  // mu_min, mu_max and compaction_drag (GroundFieldInfo::log_scale).
  std::optional<bool> log;
  std::string tie;  // parameters with the same non-empty tie share one coordinate

  static constexpr double kMaxFriction = 5.0;  // bound on mu_min and mu_max
  bool UsesLog() const;
  std::string Name() const;  // "medium.mu_min"
  // False with the field, the value and the violated bound in *why.
  bool IsValid(std::string* why) const;
};

// One coordinate of the optimiser: a parameter, or a tie of several with equal bounds.
struct Coordinate {
  std::string name;          // the tie's name, or the parameter's Name()
  std::vector<int> members;  // indices into ParameterSet::specs()
  double lower = 0, upper = 0;
  bool log = false;
  double ToValue(double u) const;     // unit coordinate -> value (u clamped to [0, 1])
  double ToUnit(double value) const;  // value -> unit coordinate (not clamped)
};

// The free parameters, resolved against a ground table.
class ParameterSet {
 public:
  // Checks every spec, that its category exists in `table`, that no field is freed twice, that
  // the members of a tie share field bounds and transform, and that mu_min <= mu_max is possible
  // within the bounds of each category. Throws talus::InputError naming the parameter.
  ParameterSet(std::vector<ParameterSpec> specs, const GroundTable& table);

  int size() const { return static_cast<int>(coordinates_.size()); }  // optimiser dimension
  const std::vector<ParameterSpec>& specs() const { return specs_; }
  const std::vector<Coordinate>& coordinates() const { return coordinates_; }

  // The parameter values (one per coordinate) of a unit vector.
  Eigen::VectorXd Values(const Eigen::VectorXd& u) const;
  // The unit vector of the values `table` holds (not clamped: a table outside the bounds gives
  // coordinates outside [0, 1]). A tie takes its first member's value.
  Eigen::VectorXd UnitOf(const GroundTable& table) const;

  // Writes the values of unit vector u into `table` (only the freed fields), then checks every
  // category it touched with GroundParams::IsValid (which includes mu_min <= mu_max). False, with
  // the reason in *why, when u is not finite, lies outside [0, 1] or a check fails: the table is
  // then edited but invalid and must not be run. *violation (when given) measures how far u is
  // from feasibility: the largest mu_min - mu_max over the touched categories (if > 0) plus the
  // distance of u outside the unit cube (0 when feasible; infinity for a non-finite u).
  bool Apply(const Eigen::VectorXd& u, GroundTable& table, std::string* why,
             double* violation = nullptr) const;

 private:
  std::vector<ParameterSpec> specs_;
  std::vector<int> category_index_;  // per spec, into the table given at construction
  std::vector<Coordinate> coordinates_;
};

}  // namespace talus::calibration
