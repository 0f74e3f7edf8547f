#include "calibration/parameters.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/error.hpp"

namespace talus::calibration {

namespace {
constexpr GroundField kAllFields[] = {GroundField::kMuMin,         GroundField::kMuMax,
                                      GroundField::kBeta,          GroundField::kKappa,
                                      GroundField::kNu,            GroundField::kSoilStrength,
                                      GroundField::kCompactionDrag};
}  // namespace

// The enum's order is the table's: every calibrated row, in order, first.
static_assert(std::size(kAllFields) <= std::tuple_size_v<decltype(kGroundFields)>);

const GroundFieldInfo& InfoOf(GroundField field) {
  return kGroundFields[static_cast<std::size_t>(field)];
}

const char* ToString(GroundField field) { return InfoOf(field).key; }

const char* UnitOf(GroundField field) { return InfoOf(field).unit; }

bool ParseGroundField(const std::string& name, GroundField* field) {
  for (GroundField f : kAllFields)
    if (name == ToString(f)) {
      *field = f;
      return true;
    }
  return false;
}

double& FieldOf(GroundParams& p, GroundField field) { return p.*InfoOf(field).member; }

double FieldOf(const GroundParams& p, GroundField field) { return p.*InfoOf(field).member; }

namespace {
struct ShapeFieldInfo {
  ShapeField field;
  const char* key;
  const char* unit;
};
constexpr ShapeFieldInfo kShapeFields[] = {{ShapeField::kRoughness, "roughness", "1"},
                                           {ShapeField::kSizeX, "size_x_m", "m"},
                                           {ShapeField::kSizeY, "size_y_m", "m"},
                                           {ShapeField::kSizeZ, "size_z_m", "m"}};
}  // namespace

const char* ToString(ShapeField field) { return kShapeFields[static_cast<int>(field)].key; }

const char* UnitOf(ShapeField field) { return kShapeFields[static_cast<int>(field)].unit; }

bool ParseShapeField(const std::string& name, ShapeField* field) {
  for (const ShapeFieldInfo& info : kShapeFields)
    if (name == info.key) {
      *field = info.field;
      return true;
    }
  return false;
}

double& KnobOf(ensemble::ShapeKnobs& knobs, ShapeField field) {
  switch (field) {
    case ShapeField::kRoughness:
      return knobs.roughness;
    case ShapeField::kSizeX:
      return knobs.size_m.x();
    case ShapeField::kSizeY:
      return knobs.size_m.y();
    case ShapeField::kSizeZ:
      break;
  }
  return knobs.size_m.z();
}

double KnobOf(const ensemble::ShapeKnobs& knobs, ShapeField field) {
  return KnobOf(const_cast<ensemble::ShapeKnobs&>(knobs), field);
}

bool ParameterSpec::UsesLog() const {
  return log.value_or(IsShape() ? false : InfoOf(field).log_scale);
}

std::string ParameterSpec::Name() const {
  return IsShape() ? "blocks." + block + "." + FieldName() : category + "." + FieldName();
}

std::string ParameterSpec::FieldName() const {
  return IsShape() ? ToString(shape_field) : ToString(field);
}

const char* ParameterSpec::Unit() const {
  return IsShape() ? UnitOf(shape_field) : UnitOf(field);
}

bool ParameterSpec::IsValid(std::string* why) const {
  std::ostringstream msg;
  const bool friction = !IsShape() && (field == GroundField::kMuMin || field == GroundField::kMuMax);
  const bool roughness = IsShape() && shape_field == ShapeField::kRoughness;
  if (category.empty() && !IsShape())
    msg << "category is empty";
  else if (!category.empty() && IsShape())
    msg << "names both a ground category and a block";
  else if (roughness && (!std::isfinite(lower) || lower < 0 || (UsesLog() && lower == 0)))
    msg << "lower = " << lower << " must be >= 0 (> 0 on a log scale)";
  else if (!roughness && (!std::isfinite(lower) || !(lower > 0)))
    msg << "lower = " << lower << " must be > 0 ("
        << (IsShape() ? "a size is positive" : "every ground parameter is positive") << ")";
  else if (!std::isfinite(upper) || !(upper > lower))
    msg << "upper = " << upper << " must be > lower = " << lower << " (the bounds are empty)";
  else if (friction && upper > kMaxFriction)
    msg << "upper = " << upper << " must be <= " << kMaxFriction << " for a friction coefficient";
  else if (roughness && upper > kMaxRoughness)
    msg << "upper = " << upper << " must be <= " << kMaxRoughness << " for a roughness";
  else if (prior && !(std::isfinite(prior->mean) && std::isfinite(prior->sd) &&
                      std::isfinite(prior->factor)))
    msg << "prior: mean, sd and factor must be finite";
  else if (prior && (prior->sd > 0) == (prior->factor > 0))
    msg << "prior: give sd (> 0, a normal prior) or factor (> 1, a log-normal one), one of them";
  else if (prior && prior->IsLogNormal() && !(prior->factor > 1))
    msg << "prior: factor = " << prior->factor << " must be > 1 (one sd is this factor)";
  else if (prior && (prior->sd < 0 || prior->factor < 0))
    msg << "prior: sd and factor must be positive";
  else if (prior && prior->IsLogNormal() && !(prior->mean > 0))
    msg << "prior: mean = " << prior->mean << " must be > 0 for a log-normal prior";
  else if (prior && prior->IsLogNormal() && !(lower > 0))
    msg << "prior: a log-normal prior needs lower > 0 (at " << lower
        << " its log would be infinite): raise the lower bound";
  else if (prior && !(prior->mean >= lower && prior->mean <= upper))
    msg << "prior: mean = " << prior->mean << " lies outside the bounds [" << lower << ", " << upper
        << "] (the prior would pull against a bound: widen the bounds)";
  if (msg.str().empty()) return true;
  if (why) *why = Name() + ": " + msg.str();
  return false;
}

double Prior::Residual(double value) const {
  return IsLogNormal() ? std::log(value / mean) / std::log(factor) : (value - mean) / sd;
}

std::string Prior::Describe() const {
  std::ostringstream text;
  text.precision(6);
  if (IsLogNormal())
    text << "log-normal(" << mean << ", factor " << factor << ")";
  else
    text << "normal(" << mean << ", sd " << sd << ")";
  return text.str();
}

double Coordinate::ToValue(double u) const {
  u = std::clamp(u, 0.0, 1.0);
  if (u == 0) return lower;  // exact at the ends, whatever the rounding of the transform
  if (u == 1) return upper;
  if (log) return std::exp(std::log(lower) + u * (std::log(upper) - std::log(lower)));
  return lower + u * (upper - lower);
}

double Coordinate::ToUnit(double value) const {
  if (log) return (std::log(value) - std::log(lower)) / (std::log(upper) - std::log(lower));
  return (value - lower) / (upper - lower);
}

ParameterSet::ParameterSet(std::vector<ParameterSpec> specs, const GroundTable& table,
                           const std::vector<ensemble::Block>& blocks)
    : specs_(std::move(specs)) {
  if (specs_.empty()) throw InputError("no free parameter");
  for (const ensemble::Block& b : blocks) base_knobs_.push_back(b.knobs);
  for (std::size_t k = 0; k < specs_.size(); ++k) {
    const ParameterSpec& s = specs_[k];
    std::string why;
    if (!s.IsValid(&why)) throw InputError(why);
    if (s.IsShape()) {
      ResolveShape(s, blocks);
    } else {
      const int index = table.IndexOfName(s.category);
      if (index < 0) throw InputError(s.Name() + ": no ground category '" + s.category + "'");
      category_index_.push_back(index);
      block_index_.push_back(-1);
      if (InfoOf(s.field).group == GroundFieldInfo::Group::kSoil && !table.params(index).IsSoil())
        throw InputError(s.Name() + ": category '" + s.category +
                         "' has no scarring soil (a soil parameter acts only with model = "
                         "\"lu2019\")");
    }
    for (std::size_t j = 0; j < k; ++j)
      if (specs_[j].Name() == s.Name()) throw InputError(s.Name() + ": freed twice");
    // A tie named as another free parameter that is not in the tie would label this parameter's
    // values with that one's name (tie = "medium.mu_max" on mu_min swapped the labels).
    if (!s.tie.empty())
      for (const ParameterSpec& other : specs_)
        if (&other != &s && other.Name() == s.tie && other.tie != s.tie)
          throw InputError(
              s.Name() + ": tie '" + s.tie + "' is the name of the free parameter " + other.Name() +
              ", which is not in the tie" +
              (other.tie.empty() ? std::string() : " (its tie is '" + other.tie + "')") +
              ": name the tie otherwise (e.g. '" + s.FieldName() + "'), or give " +
              other.Name() + " the same tie");
    // A tie joins the coordinate of its name; else the parameter has a coordinate of its own.
    Coordinate* joined = nullptr;
    if (!s.tie.empty())
      for (Coordinate& c : coordinates_)
        if (c.name == s.tie) joined = &c;
    if (joined) {
      const ParameterSpec& first = specs_[joined->members.front()];
      if (first.IsShape() != s.IsShape() || first.FieldName() != s.FieldName() ||
          first.lower != s.lower || first.upper != s.upper || first.UsesLog() != s.UsesLog())
        throw InputError(s.Name() + ": tie '" + s.tie + "' joins parameters of one field with " +
                         "equal bounds and transform, unlike " + first.Name());
      if (s.prior && joined->prior && !(*s.prior == *joined->prior))
        throw InputError(s.Name() + ": tie '" + s.tie + "' has two priors, " +
                         joined->prior->Describe() + " and " + s.prior->Describe() +
                         ": state one (or the same on every member)");
      if (s.prior) joined->prior = s.prior;
      joined->members.push_back(static_cast<int>(k));
      continue;
    }
    Coordinate c;
    c.name = s.tie.empty() ? s.Name() : s.tie;
    for (const Coordinate& other : coordinates_)
      if (other.name == c.name) throw InputError(s.Name() + ": name '" + c.name + "' used twice");
    c.members = {static_cast<int>(k)};
    c.lower = s.lower;
    c.upper = s.upper;
    c.log = s.UsesLog();
    c.prior = s.prior;
    coordinates_.push_back(c);
  }
  // mu_min <= mu_max must be possible in every category: the lowest mu_min against the highest
  // mu_max (free ones at their bounds, fixed ones at the table's value).
  for (int category = 0; category < table.size(); ++category) {
    double lowest_min = table.params(category).mu_min;
    double highest_max = table.params(category).mu_max;
    bool touched = false;
    for (std::size_t k = 0; k < specs_.size(); ++k) {
      if (category_index_[k] != category) continue;
      touched = true;
      if (specs_[k].field == GroundField::kMuMin) lowest_min = specs_[k].lower;
      if (specs_[k].field == GroundField::kMuMax) highest_max = specs_[k].upper;
    }
    if (touched && lowest_min > highest_max) {
      std::ostringstream msg;
      msg << table.category(category).name << ": mu_min >= " << lowest_min
          << " and mu_max <= " << highest_max
          << " within the bounds: no parameter vector has mu_min <= mu_max";
      throw InputError(msg.str());
    }
  }
}

Eigen::VectorXd ParameterSet::Values(const Eigen::VectorXd& u) const {
  Eigen::VectorXd v(size());
  for (int j = 0; j < size(); ++j) v[j] = coordinates_[j].ToValue(u[j]);
  return v;
}

Eigen::VectorXd ParameterSet::UnitOf(const GroundTable& table) const {
  Eigen::VectorXd u(size());
  for (int j = 0; j < size(); ++j) {
    const auto k = static_cast<std::size_t>(coordinates_[j].members.front());
    const double value =
        specs_[k].IsShape()
            ? KnobOf(base_knobs_[static_cast<std::size_t>(block_index_[k])], specs_[k].shape_field)
            : FieldOf(table.params(category_index_[k]), specs_[k].field);
    u[j] = coordinates_[j].ToUnit(value);
  }
  return u;
}

void ParameterSet::ResolveShape(const ParameterSpec& s, const std::vector<ensemble::Block>& blocks) {
  int index = -1;
  for (std::size_t b = 0; b < blocks.size(); ++b)
    if (blocks[b].id == s.block) index = static_cast<int>(b);
  if (index < 0)
    throw InputError(s.Name() + ": no block '" + s.block + "'" +
                     (blocks.empty() ? std::string(" (the release has no [blocks])") : ""));
  const ensemble::Block& block = blocks[static_cast<std::size_t>(index)];
  if (!block.make)
    throw InputError(s.Name() + ": block '" + s.block +
                     "' has a fixed shape (a point cloud): only built-in blocks have knobs");
  if (!std::isfinite(KnobOf(block.knobs, s.shape_field)))
    throw InputError(s.Name() + ": block '" + s.block + "' has no " + s.FieldName() +
                     (s.shape_field == ShapeField::kRoughness ? " (only a rock block has one)"
                                                              : ""));
  category_index_.push_back(-1);
  block_index_.push_back(index);
  has_shapes_ = true;
}

bool ParameterSet::ApplyShapes(const Eigen::VectorXd& u, std::vector<ensemble::Block>& blocks,
                               std::string* why) const {
  if (!has_shapes_) return true;
  std::vector<bool> touched(blocks.size(), false);
  for (int j = 0; j < size(); ++j) {
    const double value = coordinates_[j].ToValue(std::clamp(u[j], 0.0, 1.0));
    for (int k : coordinates_[j].members) {
      const ParameterSpec& s = specs_[static_cast<std::size_t>(k)];
      if (!s.IsShape()) continue;
      const auto b = static_cast<std::size_t>(block_index_[static_cast<std::size_t>(k)]);
      KnobOf(blocks[b].knobs, s.shape_field) = value;
      touched[b] = true;
    }
  }
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    if (!touched[b]) continue;
    try {
      blocks[b].shape = std::make_shared<const RockShape>(blocks[b].make(blocks[b].knobs));
    } catch (const InputError& e) {
      if (why) *why = "block '" + blocks[b].id + "': " + e.what();
      return false;
    }
  }
  return true;
}

bool ParameterSet::Apply(const Eigen::VectorXd& u, GroundTable& table, std::string* why,
                         double* violation) const {
  double outside = 0;
  std::ostringstream msg;
  if (u.size() != size()) {
    msg << "vector of " << u.size() << " coordinates for " << size() << " parameters";
    if (why) *why = msg.str();
    if (violation) *violation = std::numeric_limits<double>::infinity();
    return false;
  }
  for (int j = 0; j < size(); ++j) {
    if (!std::isfinite(u[j])) {
      if (why) *why = coordinates_[j].name + ": coordinate is not finite";
      if (violation) *violation = std::numeric_limits<double>::infinity();
      return false;
    }
    const double d = std::max(0.0, std::max(-u[j], u[j] - 1));
    if (d > 0 && msg.str().empty())
      msg << coordinates_[j].name << ": coordinate " << u[j] << " outside [0, 1]";
    outside += d;
  }
  for (int j = 0; j < size(); ++j) {
    const double value = coordinates_[j].ToValue(u[j]);
    for (int k : coordinates_[j].members)
      if (!specs_[k].IsShape())
        FieldOf(table.mutable_params(category_index_[k]), specs_[k].field) = value;
  }
  double crossing = 0;
  for (std::size_t k = 0; k < specs_.size(); ++k) {
    if (specs_[k].IsShape()) continue;
    const GroundParams& p = table.params(category_index_[k]);
    std::string reason;
    if (!p.IsValid(&reason)) {
      crossing = std::max(crossing, p.mu_min - p.mu_max);
      if (msg.str().empty()) msg << specs_[k].category << ": " << reason;
    }
  }
  if (violation) *violation = outside + std::max(0.0, crossing);
  if (msg.str().empty()) return true;
  if (why) *why = msg.str();
  return false;
}

}  // namespace talus::calibration
