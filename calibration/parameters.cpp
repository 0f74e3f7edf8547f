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

bool ParameterSpec::UsesLog() const {
  return log.value_or(InfoOf(field).log_scale);
}

std::string ParameterSpec::Name() const { return category + "." + ToString(field); }

bool ParameterSpec::IsValid(std::string* why) const {
  std::ostringstream msg;
  const bool friction = field == GroundField::kMuMin || field == GroundField::kMuMax;
  if (category.empty())
    msg << "category is empty";
  else if (!std::isfinite(lower) || !(lower > 0))
    msg << "lower = " << lower << " must be > 0 (every ground parameter is positive)";
  else if (!std::isfinite(upper) || !(upper > lower))
    msg << "upper = " << upper << " must be > lower = " << lower << " (the bounds are empty)";
  else if (friction && upper > kMaxFriction)
    msg << "upper = " << upper << " must be <= " << kMaxFriction << " for a friction coefficient";
  if (msg.str().empty()) return true;
  if (why) *why = Name() + ": " + msg.str();
  return false;
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

ParameterSet::ParameterSet(std::vector<ParameterSpec> specs, const GroundTable& table)
    : specs_(std::move(specs)) {
  if (specs_.empty()) throw InputError("no free parameter");
  for (std::size_t k = 0; k < specs_.size(); ++k) {
    const ParameterSpec& s = specs_[k];
    std::string why;
    if (!s.IsValid(&why)) throw InputError(why);
    const int index = table.IndexOfName(s.category);
    if (index < 0) throw InputError(s.Name() + ": no ground category '" + s.category + "'");
    category_index_.push_back(index);
    if (InfoOf(s.field).group == GroundFieldInfo::Group::kSoil && !table.params(index).IsSoil())
      throw InputError(s.Name() + ": category '" + s.category +
                       "' has no scarring soil (a soil parameter acts only with model = "
                       "\"lu2019\")");
    for (std::size_t j = 0; j < k; ++j)
      if (specs_[j].category == s.category && specs_[j].field == s.field)
        throw InputError(s.Name() + ": freed twice");
    // A tie named as another free parameter that is not in the tie would label this parameter's
    // values with that one's name (tie = "medium.mu_max" on mu_min swapped the labels).
    if (!s.tie.empty())
      for (const ParameterSpec& other : specs_)
        if (&other != &s && other.Name() == s.tie && other.tie != s.tie)
          throw InputError(
              s.Name() + ": tie '" + s.tie + "' is the name of the free parameter " + other.Name() +
              ", which is not in the tie" +
              (other.tie.empty() ? std::string() : " (its tie is '" + other.tie + "')") +
              ": name the tie otherwise (e.g. '" + ToString(s.field) + "'), or give " +
              other.Name() + " the same tie");
    // A tie joins the coordinate of its name; else the parameter has a coordinate of its own.
    Coordinate* joined = nullptr;
    if (!s.tie.empty())
      for (Coordinate& c : coordinates_)
        if (c.name == s.tie) joined = &c;
    if (joined) {
      const ParameterSpec& first = specs_[joined->members.front()];
      if (first.field != s.field || first.lower != s.lower || first.upper != s.upper ||
          first.UsesLog() != s.UsesLog())
        throw InputError(s.Name() + ": tie '" + s.tie + "' joins parameters of one field with " +
                         "equal bounds and transform, unlike " + first.Name());
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
    const int k = coordinates_[j].members.front();
    u[j] = coordinates_[j].ToUnit(FieldOf(table.params(category_index_[k]), specs_[k].field));
  }
  return u;
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
      FieldOf(table.mutable_params(category_index_[k]), specs_[k].field) = value;
  }
  double crossing = 0;
  for (std::size_t k = 0; k < specs_.size(); ++k) {
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
