#pragma once
// The pieces the options tables (kSolverOptions, kGroundFields) are made of: the names of an
// enum's values, and the bounds of a value.

#include <limits>
#include <span>
#include <string>
#include <string_view>

namespace talus {

// The names of one enum's values as scene files, summary.json and the docs give them: ToString,
// parsing and the "known: ..." of messages all read this one list. Enumerator k (in declaration
// order, numbered 0, 1, ...) is names[k].
struct EnumNames {
  const char* what;  // what one value is called in messages: "unknown <what> 'x'"
  std::span<const char* const> names;

  int size() const { return static_cast<int>(names.size()); }
  // "unknown" when `value` is no enumerator's number.
  const char* Name(int value) const;
  // The number of the enumerator named `name`, or -1.
  int Find(std::string_view name) const;
  // "a, b, c".
  std::string List() const;

  template <class Enum>
  const char* NameOf(Enum value) const {
    return Name(static_cast<int>(value));
  }
  // False, leaving *value as it is, when `name` is no enumerator's name.
  template <class Enum>
  bool Parse(std::string_view name, Enum* value) const {
    const int k = Find(name);
    if (k < 0) return false;
    *value = static_cast<Enum>(k);
    return true;
  }
};

// The valid values of a number: lower <= value <= upper, with < at an open end; always finite.
// An infinite end is no bound.
struct Bounds {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  double lower = -kInf, upper = kInf;
  bool lower_open = false, upper_open = false;

  static constexpr Bounds Between(double lo, double hi) { return {lo, hi, false, false}; }
  static constexpr Bounds Inside(double lo, double hi) { return {lo, hi, true, true}; }
  static constexpr Bounds AboveAtMost(double lo, double hi) { return {lo, hi, true, false}; }
  static constexpr Bounds AtLeast(double lo) { return {lo, kInf, false, false}; }
  static constexpr Bounds Above(double lo) { return {lo, kInf, true, false}; }

  bool Contains(double value) const;
  // The bounds as a condition on `name`: "0 < dt_s <= 0.1", "max_time_s > 0",
  // "1 <= max_iterations <= 100000" (numbers as an ostream writes them).
  std::string Describe(std::string_view name) const;
  // As an interval: "(0, 1)", "[1, 100000]", "(0, inf)".
  std::string Interval() const;
};

}  // namespace talus
