#include "io/calibration_checkpoint.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/error.hpp"
#include "common/sha256.hpp"

namespace talus::io {
namespace {

using calibration::Evaluation;
using nlohmann::json;

// NaN (and infinities, which an evaluation does not hold) as null.
json Number(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
double NumberOf(const json& j) {
  return j.is_null() ? std::numeric_limits<double>::quiet_NaN() : j.get<double>();
}

json Vector(const Eigen::VectorXd& v) {
  json out = json::array();
  for (Eigen::Index k = 0; k < v.size(); ++k) out.push_back(Number(v[k]));
  return out;
}
Eigen::VectorXd VectorOf(const json& j) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(j.size()));
  for (std::size_t k = 0; k < j.size(); ++k) v[static_cast<Eigen::Index>(k)] = NumberOf(j[k]);
  return v;
}

json ToJson(const Evaluation& e) {
  json scores = json::array();
  for (double s : e.kind_scores) scores.push_back(Number(s));
  return {{"u", Vector(e.u)},
          {"values", Vector(e.values)},
          {"feasible", e.feasible},
          {"infeasible", e.infeasible},
          {"value", Number(e.value)},
          {"data", Number(e.data)},
          {"prior", Number(e.prior)},
          {"kind_scores", scores},
          {"kind_scored", e.kind_scored},
          {"residuals", Vector(e.residuals)},
          {"rocks", e.rocks},
          {"failed_rocks", e.failed_rocks},
          {"wall_time_s", e.wall_time_s}};
}

Evaluation EvaluationOf(const json& j) {
  Evaluation e;
  e.u = VectorOf(j.at("u"));
  e.values = VectorOf(j.at("values"));
  e.feasible = j.at("feasible").get<bool>();
  e.infeasible = j.at("infeasible").get<std::string>();
  e.value = NumberOf(j.at("value"));
  e.data = NumberOf(j.at("data"));
  e.prior = NumberOf(j.at("prior"));
  for (const json& s : j.at("kind_scores")) e.kind_scores.push_back(NumberOf(s));
  e.kind_scored = j.at("kind_scored").get<std::vector<int>>();
  e.residuals = VectorOf(j.at("residuals"));
  e.rocks = j.at("rocks").get<long>();
  e.failed_rocks = j.at("failed_rocks").get<long>();
  e.wall_time_s = j.at("wall_time_s").get<double>();
  return e;
}

// What the checkpoint holds, without its checksum: writing what was read gives the same bytes.
json Body(const CalibrationCheckpoint& c) {
  json stages = json::object();
  for (const auto& [name, evaluations] : c.stages) {
    json list = json::array();
    for (const Evaluation& e : evaluations) list.push_back(ToJson(e));
    stages[name] = list;
  }
  return {
      {"path_sha256", c.path_hash}, {"holdout", c.holdout}, {"folds", c.folds}, {"stages", stages}};
}

// "" when `e` fits `shape` and holds finite numbers where an evaluation always does (u, values,
// residuals, prior, and the value of a feasible one; data and the kinds' scores are NaN when not
// computed), else what is wrong.
std::string CheckEvaluation(const Evaluation& e, const EvaluationShape& shape) {
  // Appended piece by piece (GCC 12 warns wrongly about chains of std::string operator+).
  const auto size = [](const char* key, long have, int want, const char* what) {
    std::string out = "\"";
    out.append(key).append("\" has ").append(std::to_string(have));
    out.append(" entries, the calibration ").append(std::to_string(want)).append(" ").append(what);
    return out;
  };
  if (e.u.size() != shape.dimension) return size("u", e.u.size(), shape.dimension, "parameters");
  if (e.values.size() != shape.dimension)
    return size("values", e.values.size(), shape.dimension, "parameters");
  const auto kinds = static_cast<long>(e.kind_scores.size());
  if (kinds != shape.kinds) return size("kind_scores", kinds, shape.kinds, "observation kinds");
  if (static_cast<long>(e.kind_scored.size()) != shape.kinds)
    return size("kind_scored", static_cast<long>(e.kind_scored.size()), shape.kinds,
                "observation kinds");
  if (e.residuals.size() != shape.residuals)
    return size("residuals", e.residuals.size(), shape.residuals, "residuals");
  if (!e.u.allFinite()) return "\"u\" holds a number that is not finite";
  if (!e.values.allFinite()) return "\"values\" holds a number that is not finite";
  if (!e.residuals.allFinite()) return "\"residuals\" holds a number that is not finite";
  if (e.feasible && !std::isfinite(e.value)) return "\"value\" is not a finite number";
  if (!std::isfinite(e.prior)) return "\"prior\" is not a finite number";
  if (e.rocks < 0 || e.failed_rocks < 0 || e.failed_rocks > e.rocks)
    return "\"rocks\" and \"failed_rocks\" are not counts of rocks";
  return "";
}

}  // namespace

std::string CheckpointJson(const CalibrationCheckpoint& c) {
  json j = Body(c);
  j["sha256"] = Sha256Hex(j.dump());
  return j.dump() + "\n";
}

CalibrationCheckpoint ReadCheckpoint(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot read the checkpoint");
  std::stringstream text;
  text << in.rdbuf();
  const std::string start_afresh =
      "remove it and run talus calibrate without --resume to start afresh";
  CalibrationCheckpoint c;
  std::string saved_hash;
  try {
    const json j = json::parse(text.str());
    // An older talus checksummed a checkpoint with FNV-1a 64 ("fnv1a64") and tied it to its
    // calibration by an FNV-1a hash too: neither can be checked or matched any more.
    if (j.is_object() && j.contains("fnv1a64"))
      throw InputError(path +
                       ": a checkpoint of an older talus (its checksum is FNV-1a, \"fnv1a64\"; "
                       "this talus checks SHA-256), which cannot be resumed: " +
                       start_afresh);
    c.path_hash = j.at("path_sha256").get<std::string>();
    c.holdout = j.at("holdout").get<std::vector<std::string>>();
    c.folds = j.at("folds").get<int>();
    for (const auto& [name, list] : j.at("stages").items())
      for (const json& e : list) c.stages[name].push_back(EvaluationOf(e));
    if (!j.contains("sha256"))
      throw InputError(path + ": the checkpoint has no checksum (\"sha256\"): " + start_afresh);
    saved_hash = j.at("sha256").get<std::string>();
  } catch (const json::exception& e) {
    throw InputError(path + ": not a calibration checkpoint: " + e.what());
  }
  if (const std::string hash = Sha256Hex(Body(c).dump()); hash != saved_hash)
    throw InputError(path + ": what the checkpoint holds does not match its checksum (sha256 " +
                     saved_hash + ", the contents give " + hash +
                     "): the file was edited or damaged; " + start_afresh);
  return c;
}

void CheckEvaluations(const CalibrationCheckpoint& c, const std::string& path,
                      const std::map<std::string, EvaluationShape>& shapes) {
  for (const auto& [name, evaluations] : c.stages) {
    const auto shape = shapes.find(name);
    if (shape == shapes.end())
      throw InputError(path + ": stages." + name +
                       ": this calibration has no such optimisation; remove the checkpoint to "
                       "start afresh");
    for (std::size_t k = 0; k < evaluations.size(); ++k)
      if (const std::string why = CheckEvaluation(evaluations[k], shape->second); !why.empty())
        throw InputError(path + ": stages." + name + "[" + std::to_string(k) + "]: " + why +
                         "; remove the checkpoint to start afresh");
  }
}

}  // namespace talus::io
