#pragma once
// Typed, checked access to the tables of a TOML input file (scenes, events, calibrations), with
// errors "<file>:<line>: <key>: <reason>" and "did you mean" hints for unknown keys. Internal to
// io/: include it from .cpp files only (it brings in toml++).

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "common/closest_name.hpp"
#include "common/error.hpp"
#include "common/format.hpp"

namespace talus::io {

// Reads a TOML file (a scene, event or calibration file: `what`), with errors "<path>: <what> not
// found", "<path>: is a directory, not the <what>" and "<path>:<line>: TOML syntax error: ...".
inline toml::table ParseTomlFile(const std::string& path, const std::string& what) {
  if (!std::filesystem::exists(path)) throw InputError(path + ": " + what + " not found");
  if (std::filesystem::is_directory(path))
    throw InputError(path + ": is a directory, not the " + what);
  try {
    return toml::parse_file(path);
  } catch (const toml::parse_error& e) {
    throw InputError(path + ":" + std::to_string(e.source().begin.line) +
                     ": TOML syntax error: " + std::string(e.description()));
  }
}

// The file being loaded: resolves paths and formats errors as "<file>:<line>: <key>: <reason>".
class Context {
 public:
  explicit Context(std::string file)
      : file_(std::move(file)), dir_(std::filesystem::path(file_).parent_path()) {}

  [[noreturn]] void Fail(const toml::node* node, const std::string& key,
                         const std::string& reason) const {
    throw InputError(Where(node) + ": " + key + ": " + reason);
  }
  std::string Where(const toml::node* node) const {
    if (node && node->source().begin.line > 0)
      return file_ + ":" + std::to_string(node->source().begin.line);
    return file_;
  }
  std::string Resolve(const std::string& path) const {
    const std::filesystem::path p(path);
    return (p.is_absolute() ? p : dir_ / p).lexically_normal().string();
  }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
  std::filesystem::path dir_;
};

// One table of the scene: typed access to its keys; keys not in `known` are errors.
class Section {
 public:
  Section(const Context& context, const toml::table* table, std::string name,
          std::vector<std::string> known)
      : context_(context), table_(table), name_(std::move(name)), known_(std::move(known)) {
    if (!table_) return;
    for (const auto& [key, node] : *table_) {
      const std::string k(key.str());
      if (std::find(known_.begin(), known_.end(), k) != known_.end()) continue;
      const std::string hint = ClosestName(k, known_);
      context_.Fail(&node, Key(k),
                    "unknown key" + (hint.empty() ? "" : " (did you mean '" + hint + "'?)"));
    }
  }

  std::string Key(const std::string& key) const { return name_.empty() ? key : name_ + "." + key; }
  const toml::node* Node(const std::string& key) const {
    return table_ ? table_->get(key) : nullptr;
  }
  bool Has(const std::string& key) const { return Node(key) != nullptr; }
  [[noreturn]] void Fail(const std::string& key, const std::string& reason) const {
    context_.Fail(Node(key) ? Node(key) : static_cast<const toml::node*>(table_), Key(key), reason);
  }

  // Fails with the reason an options check gave (the IsValid functions' "<field> = <value> ...",
  // fields named as the keys) on the line of the key that set <field>; on the table's line when
  // the table does not set it (a default that another key's value violates).
  [[noreturn]] void FailCheck(const std::string& why) const {
    const std::string field = why.substr(0, why.find(' '));
    if (Has(field)) Fail(field, why);
    context_.Fail(table_, name_, why);
  }

  double Number(const std::string& key, double fallback) const {
    const toml::node* node = Node(key);
    if (!node) return fallback;
    if (auto v = node->value<double>(); v && (node->is_integer() || node->is_floating_point()))
      return *v;
    Fail(key, "expected a number");
  }
  // A number that must satisfy `ok`, described by `bound` ("must be > 0").
  template <class Pred>
  double Checked(const std::string& key, double fallback, Pred ok, const std::string& bound) const {
    const double v = Number(key, fallback);
    if (!std::isfinite(v) || !ok(v)) Fail(key, TenDigits(v) + " " + bound);
    return v;
  }
  long Integer(const std::string& key, long fallback) const {
    const toml::node* node = Node(key);
    if (!node) return fallback;
    if (!node->is_integer()) Fail(key, "expected an integer");
    return static_cast<long>(*node->value<std::int64_t>());
  }
  bool Bool(const std::string& key, bool fallback) const {
    const toml::node* node = Node(key);
    if (!node) return fallback;
    if (!node->is_boolean()) Fail(key, "expected true or false");
    return *node->value<bool>();
  }
  std::string String(const std::string& key, const std::string& fallback) const {
    const toml::node* node = Node(key);
    if (!node) return fallback;
    if (!node->is_string()) Fail(key, "expected a string");
    return std::string(*node->value<std::string>());
  }
  // A list of exactly n numbers.
  std::vector<double> Numbers(const std::string& key, std::size_t n) const {
    return NumbersOf(Node(key), Key(key), n);
  }
  std::vector<double> NumbersOf(const toml::node* node, const std::string& key,
                                std::size_t n) const {
    const toml::array* array = node ? node->as_array() : nullptr;
    if (!array || array->size() != n)
      context_.Fail(node, key, "expected a list of " + std::to_string(n) + " numbers");
    std::vector<double> out;
    for (const toml::node& item : *array) {
      const auto v = item.value<double>();
      if (!v || !(item.is_integer() || item.is_floating_point()) || !std::isfinite(*v))
        context_.Fail(node, key, "expected a list of " + std::to_string(n) + " finite numbers");
      out.push_back(*v);
    }
    return out;
  }
  const toml::table* table() const { return table_; }
  const Context& context() const { return context_; }

 private:
  const Context& context_;
  const toml::table* table_;
  std::string name_;
  std::vector<std::string> known_;
};

// The table `key` of `root`, or null when absent; an error when it is not a table.
inline const toml::table* SubTable(const Context& context, const toml::table& root,
                                   const std::string& key) {
  const toml::node* node = root.get(key);
  if (!node) return nullptr;
  if (!node->is_table()) context.Fail(node, key, "expected a table ([" + key + "])");
  return node->as_table();
}

}  // namespace talus::io
