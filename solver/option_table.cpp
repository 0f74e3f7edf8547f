#include "solver/option_table.hpp"

#include <cmath>
#include <sstream>

namespace talus {

const char* EnumNames::Name(int value) const {
  if (value < 0 || value >= size()) return "unknown";
  return names[static_cast<std::size_t>(value)];
}

int EnumNames::Find(std::string_view name) const {
  for (int k = 0; k < size(); ++k)
    if (name == names[static_cast<std::size_t>(k)]) return k;
  return -1;
}

std::string EnumNames::List() const {
  std::string list;
  for (const char* name : names) list += (list.empty() ? "" : ", ") + std::string(name);
  return list;
}

bool Bounds::Contains(double value) const {
  return std::isfinite(value) && (lower_open ? value > lower : value >= lower) &&
         (upper_open ? value < upper : value <= upper);
}

std::string Bounds::Describe(std::string_view name) const {
  std::ostringstream text;
  const bool has_lower = lower > -kInf, has_upper = upper < kInf;
  if (has_lower && has_upper) {
    text << lower << (lower_open ? " < " : " <= ") << name << (upper_open ? " < " : " <= ")
         << upper;
  } else if (has_lower) {
    text << name << (lower_open ? " > " : " >= ") << lower;
  } else if (has_upper) {
    text << name << (upper_open ? " < " : " <= ") << upper;
  } else {
    text << name << " finite";
  }
  return text.str();
}

std::string Bounds::Interval() const {
  std::ostringstream text;
  text << (lower_open || lower == -kInf ? "(" : "[") << lower << ", " << upper
       << (upper_open || upper == kInf ? ")" : "]");
  return text.str();
}

}  // namespace talus
