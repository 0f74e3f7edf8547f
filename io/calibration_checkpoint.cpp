#include "io/calibration_checkpoint.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "common/error.hpp"

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

}  // namespace

std::string CheckpointJson(const CalibrationCheckpoint& c) {
  json stages = json::object();
  for (const auto& [name, evaluations] : c.stages) {
    json list = json::array();
    for (const Evaluation& e : evaluations) list.push_back(ToJson(e));
    stages[name] = list;
  }
  const json j = {
      {"path_hash", c.path_hash}, {"holdout", c.holdout}, {"folds", c.folds}, {"stages", stages}};
  return j.dump() + "\n";
}

CalibrationCheckpoint ReadCheckpoint(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot read the checkpoint");
  std::stringstream text;
  text << in.rdbuf();
  try {
    const json j = json::parse(text.str());
    CalibrationCheckpoint c;
    c.path_hash = j.at("path_hash").get<std::string>();
    c.holdout = j.at("holdout").get<std::vector<std::string>>();
    c.folds = j.at("folds").get<int>();
    for (const auto& [name, list] : j.at("stages").items())
      for (const json& e : list) c.stages[name].push_back(EvaluationOf(e));
    return c;
  } catch (const json::exception& e) {
    throw InputError(path + ": not a calibration checkpoint: " + e.what());
  }
}

}  // namespace talus::io
