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
//
// A parameter is a field of a ground category, or a knob of a block's shape (a shape parameter:
// the roughness of a built-in rock block, an axis of a built-in block's size), so that ground and
// shape can be fitted together; the shape's knobs are ensemble::Block's.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "ensemble/release.hpp"
#include "solver/ground.hpp"

namespace talus::calibration {

// A coordinate within this much of 0 or 1 (1e-3 of the range) lies at its bound: the optimum may
// lie beyond the range. The calibration's warnings, the uncertainty's note and the fitted ground
// table's comments all say it by this test.
inline constexpr double kAtBoundOfRange = 1e-3;
inline bool AtLowerBound(double u) { return u <= kAtBoundOfRange; }
inline bool AtUpperBound(double u) { return u >= 1 - kAtBoundOfRange; }

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

// The knobs of a block's shape that a calibration may free (ensemble::ShapeKnobs).
enum class ShapeField { kRoughness, kSizeX, kSizeY, kSizeZ };
const char* ToString(ShapeField field);  // "roughness", "size_x_m", "size_y_m", "size_z_m"
const char* UnitOf(ShapeField field);    // "1", "m", "m", "m"
bool ParseShapeField(const std::string& name, ShapeField* field);
double& KnobOf(ensemble::ShapeKnobs& knobs, ShapeField field);
double KnobOf(const ensemble::ShapeKnobs& knobs, ShapeField field);

// What the user knows of one parameter before the fit, in the field's unit: a normal prior
// (mean, sd), e.g. a measured size and its survey error, or a log-normal one (mean, factor), for
// a parameter known to a factor (a viscosity, a scar-growth rate). Its residual r -- the value's
// distance from the mean in sds, (value - mean) / sd or ln(value / mean) / ln(factor) -- enters
// the objective as prior_weight * r^2 (objective.hpp).
struct Prior {
  double mean = 0;
  double sd = 0;      // > 0: normal
  double factor = 0;  // > 1: log-normal (one sd is this factor); sd and factor exclusive
  bool IsLogNormal() const { return factor > 0; }
  double Residual(double value) const;
  bool operator==(const Prior& o) const {
    return mean == o.mean && sd == o.sd && factor == o.factor;
  }
  std::string Describe() const;  // "normal(0.3, sd 0.05)", "log-normal(5, factor 2)"
};

// One free parameter: a field of one ground category or a knob of one block's shape, its
// physical bounds and its transform.
struct ParameterSpec {
  std::string category;  // a category of the scene's ground table, e.g. "medium"
  GroundField field = GroundField::kMuMin;
  // A shape parameter instead: a block of the release (ensemble::Block::id) and its knob; then
  // `category` is empty.
  std::string block;
  ShapeField shape_field = ShapeField::kRoughness;
  double lower = 0;  // in the field's unit; > 0 (a roughness: >= 0)
  double upper = 0;  // > lower; mu <= kMaxFriction, roughness <= kMaxRoughness
  // Log transform of the coordinate; nullopt: on for beta, kappa, nu and soil_strength, off for
  // mu_min, mu_max, compaction_drag (GroundFieldInfo::log_scale) and every shape knob.
  std::optional<bool> log;
  std::string tie;  // parameters with the same non-empty tie share one coordinate
  // Its own prior (members of a tie state the same one or none); none: the objective's reference
  // prior, if any, acts on its coordinate.
  std::optional<Prior> prior;

  static constexpr double kMaxFriction = 5.0;   // bound on mu_min and mu_max
  static constexpr double kMaxRoughness = 0.5;  // as the built-in rock takes it
  bool IsShape() const { return !block.empty(); }
  bool UsesLog() const;
  std::string Name() const;       // "medium.mu_min", or "blocks.<id>.roughness"
  std::string FieldName() const;  // "mu_min", "roughness", ...
  const char* Unit() const;       // the field's unit
  // False with the field, the value and the violated bound in *why (a prior's too: finite, a
  // positive sd or a factor above 1, its mean within the bounds).
  bool IsValid(std::string* why) const;
};

// One coordinate of the optimiser: a parameter, or a tie of several with equal bounds.
struct Coordinate {
  std::string name;          // the tie's name, or the parameter's Name()
  std::vector<int> members;  // indices into ParameterSet::specs()
  double lower = 0, upper = 0;
  bool log = false;
  std::optional<Prior> prior;         // its members' own prior, if one states it
  double ToValue(double u) const;     // unit coordinate -> value (u clamped to [0, 1])
  double ToUnit(double value) const;  // value -> unit coordinate (not clamped)
};

// The free parameters, resolved against a ground table and the release's blocks.
class ParameterSet {
 public:
  // Checks every spec, that its category exists in `table` (a shape parameter: that its block
  // is in `blocks` and has the knob), that no field is freed twice, that the members of a tie
  // share field bounds and transform, and that mu_min <= mu_max is possible within the bounds of
  // each category. Throws talus::InputError naming the parameter.
  ParameterSet(std::vector<ParameterSpec> specs, const GroundTable& table,
               const std::vector<ensemble::Block>& blocks = {});

  int size() const { return static_cast<int>(coordinates_.size()); }  // optimiser dimension
  const std::vector<ParameterSpec>& specs() const { return specs_; }
  const std::vector<Coordinate>& coordinates() const { return coordinates_; }

  // The parameter values (one per coordinate) of a unit vector.
  Eigen::VectorXd Values(const Eigen::VectorXd& u) const;
  // The unit vector of the values `table` holds, and of shape parameters the knobs of the blocks
  // given at construction (not clamped: a value outside the bounds gives a coordinate outside
  // [0, 1]). A tie takes its first member's value.
  Eigen::VectorXd UnitOf(const GroundTable& table) const;
  bool has_shapes() const { return has_shapes_; }

  // Writes the values of unit vector u into `table` (only the freed fields), then checks every
  // category it touched with GroundParams::IsValid (which includes mu_min <= mu_max). False, with
  // the reason in *why, when u is not finite, lies outside [0, 1] or a check fails: the table is
  // then edited but invalid and must not be run. *violation (when given) measures how far u is
  // from feasibility: the largest mu_min - mu_max over the touched categories (if > 0) plus the
  // distance of u outside the unit cube (0 when feasible; infinity for a non-finite u).
  // Shape parameters are not written here (ApplyShapes).
  bool Apply(const Eigen::VectorXd& u, GroundTable& table, std::string* why,
             double* violation = nullptr) const;
  // Writes the shape parameters of unit vector u (clamped to [0, 1]) into the knobs of `blocks`
  // (the blocks given at construction, in the same order) and remakes the shapes of the blocks it
  // touched. False, with the block and the reason in *why, when a shape cannot be made (e.g. a
  // size whose density, with the block's mass, is impossible): the blocks are then edited but
  // must not be run. Nothing to do, and true, without shape parameters.
  bool ApplyShapes(const Eigen::VectorXd& u, std::vector<ensemble::Block>& blocks,
                   std::string* why) const;

 private:
  std::vector<ParameterSpec> specs_;
  std::vector<int> category_index_;  // per spec, into the table given at construction; -1: shape
  std::vector<int> block_index_;     // per spec, into the blocks given at construction; -1: ground
  std::vector<ensemble::ShapeKnobs> base_knobs_;  // of the blocks given at construction
  std::vector<Coordinate> coordinates_;
  bool has_shapes_ = false;

  // The block of shape parameter `s` and its checks (the constructor's).
  void ResolveShape(const ParameterSpec& s, const std::vector<ensemble::Block>& blocks);
};

}  // namespace talus::calibration
