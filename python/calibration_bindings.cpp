// talus.Calibration: a calibration file posed as talus calibrate poses it (the same problem, the
// same common random numbers), its objective evaluated at any parameter vector -- for SciPy's
// optimisers, an MCMC sampler, a sensitivity study -- and the built-in calibration run through
// the same library call as the command (calibration::Calibrate).

#include <memory>

#include "calibration/calibrate.hpp"
#include "calibration/least_squares.hpp"
#include "io/calibration_file.hpp"
#include "io/calibration_outputs.hpp"
#include "io/summary.hpp"
#include "python/common.hpp"
#include "talus/version.hpp"

namespace talus::python {
namespace {

struct Calibration {
  io::CalibrationFile file;
  std::unique_ptr<calibration::CalibrationProblem> problem;

  const calibration::Objective& objective() const { return problem->objective(); }
};

std::string PathText(const py::object& path) {
  return py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
}

std::shared_ptr<Calibration> Load(const py::object& path, const std::string& holdout, int folds,
                                  int threads, const py::object& rocks) {
  if (threads < 0) throw InputError("threads: " + std::to_string(threads) + " must be >= 0");
  if (folds < 0 || folds == 1)
    throw InputError("folds: " + std::to_string(folds) + " must be 0 (none) or >= 2");
  const long per_run = rocks.is_none() ? 0 : rocks.cast<long>();
  if (!rocks.is_none() && per_run < 1)
    throw InputError("rocks: " + std::to_string(per_run) + " must be >= 1");
  const std::string text = PathText(path);
  return WithoutGil([&] {
    auto c = std::make_shared<Calibration>();
    c->file = io::LoadCalibration(text);
    if (per_run > 0) {
      ensemble::ReleaseSpec& release = c->file.event.scene.release;
      release.SetRocksPerRelease(per_run);
      if (std::string why; !release.IsValid(&why))
        throw InputError("rocks " + std::to_string(per_run) + ": " + why);
    }
    calibration::ObjectiveOptions objective = c->file.objective;
    objective.threads = threads;
    objective.progress = SignalCheck();
    c->problem = io::MakeCalibrationProblem(c->file, holdout, folds, objective);
    return c;
  });
}

Eigen::VectorXd VectorOf(const py::array_t<double, py::array::c_style | py::array::forcecast>& a,
                         int dimension, const char* what) {
  if (a.ndim() != 1 || a.shape(0) != dimension) {
    std::string shape;
    for (py::ssize_t k = 0; k < a.ndim(); ++k)
      shape += (k ? ", " : "") + std::to_string(a.shape(k));
    throw InputError(std::string(what) + ": expected a vector of " + std::to_string(dimension) +
                     " values (one per parameter), got shape (" + shape + ")");
  }
  Eigen::VectorXd v(dimension);
  for (int k = 0; k < dimension; ++k) v[k] = a.at(k);
  return v;
}

// Unit coordinates of parameter values (not clamped: outside the bounds is infeasible).
Eigen::VectorXd UnitOfValues(const Calibration& c, const Eigen::VectorXd& values) {
  const auto& coordinates = c.objective().parameters().coordinates();
  Eigen::VectorXd u(values.size());
  for (Eigen::Index k = 0; k < values.size(); ++k)
    u[k] = coordinates[static_cast<std::size_t>(k)].ToUnit(values[k]);
  return u;
}

py::dict EvaluationDict(const Calibration& c, const calibration::Evaluation& e) {
  py::dict kind_scores, kind_scored;
  const std::vector<std::string>& kinds = c.objective().kinds();
  for (std::size_t k = 0; k < kinds.size() && k < e.kind_scores.size(); ++k) {
    kind_scores[py::str(kinds[k])] = e.kind_scores[k];
    kind_scored[py::str(kinds[k])] = e.kind_scored[k];
  }
  py::dict d;
  d["value"] = e.value;
  d["data"] = e.data;
  d["prior"] = e.prior;
  d["feasible"] = e.feasible;
  d["infeasible"] = e.infeasible;
  d["u"] = Array(e.u);
  d["values"] = Array(e.values);
  d["kind_scores"] = kind_scores;
  d["kind_scored"] = kind_scored;
  d["residuals"] = Array(e.residuals);
  d["rocks"] = e.rocks;
  d["failed_rocks"] = e.failed_rocks;
  d["wall_time_s"] = e.wall_time_s;
  return d;
}

py::dict EvaluateUnit(const Calibration& c, const Eigen::VectorXd& u) {
  const calibration::Evaluation e = WithoutGil([&] { return c.objective().Evaluate(u); });
  return EvaluationDict(c, e);
}

py::list Parameters(const Calibration& c) {
  py::list out;
  for (const calibration::Coordinate& coordinate : c.objective().parameters().coordinates()) {
    py::dict d;
    d["name"] = coordinate.name;
    d["lower"] = coordinate.lower;
    d["upper"] = coordinate.upper;
    d["log"] = coordinate.log;
    if (coordinate.prior) {
      py::dict prior;
      prior["kind"] = coordinate.prior->IsLogNormal() ? "log-normal" : "normal";
      prior["mean"] = coordinate.prior->mean;
      if (coordinate.prior->IsLogNormal())
        prior["factor"] = coordinate.prior->factor;
      else
        prior["sd"] = coordinate.prior->sd;
      d["prior"] = prior;
    } else {
      d["prior"] = py::none();
    }
    const calibration::ParameterSpec& first =
        c.objective().parameters().specs()[static_cast<std::size_t>(coordinate.members.front())];
    d["unit"] = first.Unit();
    py::list members;
    for (int member : coordinate.members)
      members.append(c.objective().parameters().specs()[static_cast<std::size_t>(member)].Name());
    d["members"] = members;
    out.append(d);
  }
  return out;
}

// The sandwich covariance at unit coordinates u, as talus calibrate estimates it at its optimum
// (calibration::EstimateUncertainty with the file's [uncertainty] options): the central-difference
// step is fd_step, else the file's, else chosen at u by the fit's rule. Without the roughness and
// the profiles a calibration may have measured (their noise level and flat profiles).
py::dict UncertaintyAt(const Calibration& c, const Eigen::VectorXd& u, const py::object& fd_step) {
  const auto& coordinates = c.objective().parameters().coordinates();
  for (Eigen::Index k = 0; k < u.size(); ++k)
    if (!(u[k] >= 0 && u[k] <= 1))
      throw InputError(coordinates[static_cast<std::size_t>(k)].name +
                       ": the point is outside the parameter's bounds (unit coordinate " +
                       std::to_string(u[k]) + ")");
  calibration::UncertaintyOptions options = c.file.options.uncertainty_options;
  if (!fd_step.is_none()) {
    const double h = fd_step.cast<double>();
    if (!(h > 0 && h <= 0.25))
      throw InputError("fd_step: " + std::to_string(h) +
                       " must be in (0, 0.25] (unit coordinates)");
    options.fd_step = h;
  }
  std::string json, report;
  WithoutGil([&] {
    report = calibration::ChooseCovarianceStep(c.objective(), u, options);
    const calibration::Uncertainty result =
        calibration::EstimateUncertainty(c.objective(), u, options);
    json = io::UncertaintyJson(result);
    report += result.Report();
    return 0;
  });
  py::dict out = FromJson(json);
  out["report"] = report;
  return out;
}

py::dict Run(const Calibration& c, const py::object& progress, const py::object& max_evaluations) {
  calibration::CalibrationOptions options = c.file.options;
  if (!max_evaluations.is_none()) {
    const int n = max_evaluations.cast<int>();
    if (n < 1) throw InputError("max_evaluations: " + std::to_string(n) + " must be >= 1");
    options.optimizer.max_evaluations = n;
  }
  options.on_evaluation = [](const std::string&, const calibration::Evaluation&, int) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw PythonSignal{};
  };
  if (!progress.is_none())
    options.on_progress = [&progress](const std::string& text) {
      py::gil_scoped_acquire gil;
      progress(text);
    };
  const calibration::Objective& objective = c.objective();
  py::dict out;
  std::string json, ground, shapes, history;
  std::vector<std::string> warnings;
  WithoutGil([&] {
    const calibration::CalibrationSummary run = calibration::Calibrate(*c.problem, options);
    json = io::CalibrationJson(c.file, objective, run, kVersion);
    ground = io::GroundTableToml(c.file, objective, run.fitted, &run);
    if (objective.parameters().has_shapes()) shapes = io::ShapeTableToml(c.file, objective, run);
    history = io::HistoryCsv(objective, run.fit);
    warnings = calibration::CalibrationWarnings(run, objective);
    return 0;
  });
  out["calibration"] = FromJson(json);
  out["ground_table_toml"] = ground;
  if (!shapes.empty()) out["shape_table_toml"] = shapes;
  out["history_csv"] = history;
  out["warnings"] = warnings;
  return out;
}

}  // namespace

void BindCalibration(py::module_& m) {
  using Vector = py::array_t<double, py::array::c_style | py::array::forcecast>;
  py::class_<Calibration, std::shared_ptr<Calibration>>(
      m, "Calibration",
      "A calibration file (docs/calibration.md) posed as talus calibrate poses it: the event's "
      "runs less the held-out ones, the free parameters, the objective with its common random "
      "numbers. evaluate() is the objective talus calibrate minimises, to the bit; it may be "
      "called from several Python threads at once (the GIL is released while rocks run).")
      .def_static("load", &Load, py::arg("path"), py::arg("holdout") = "", py::arg("folds") = 0,
                  py::arg("threads") = 0, py::arg("rocks") = py::none(),
                  "Loads and checks a calibration file. holdout and folds are talus calibrate's "
                  "--holdout (a number of runs, or comma-separated run ids) and --folds; threads "
                  "are each evaluation's worker threads (0: all cores); rocks (per run and "
                  "evaluation) overrides the file's `rocks`.")
      .def_property_readonly("parameters", &Parameters,
                             "The optimiser's coordinates: name, bounds, unit, log transform, "
                             "the parameter's own prior (mean and sd or factor; None) and the "
                             "parameters a tie joins.")
      .def_property_readonly("dimension",
                             [](const Calibration& c) { return c.objective().dimension(); })
      .def_property_readonly(
          "kinds", [](const Calibration& c) { return c.objective().kinds(); },
          "The observation kinds the objective scores, in order.")
      .def_property_readonly("holdout", [](const Calibration& c) { return c.problem->holdout(); })
      .def_property_readonly(
          "fitted_runs",
          [](const Calibration& c) {
            std::vector<std::string> ids;
            for (const ensemble::ReleaseRun& r : c.problem->fitted_runs().release.runs)
              ids.push_back(r.id);
            return ids;
          })
      .def_property_readonly(
          "start_unit", [](const Calibration& c) { return Array(c.objective().StartPoint()); },
          "Unit coordinates of the scene's own values: where the optimiser starts.")
      .def_property_readonly(
          "start",
          [](const Calibration& c) {
            return Array(c.objective().parameters().Values(c.objective().StartPoint()));
          },
          "The scene's own values of the free parameters.")
      .def(
          "to_unit",
          [](const Calibration& c, const Vector& values) {
            return Array(UnitOfValues(c, VectorOf(values, c.objective().dimension(), "values")));
          },
          py::arg("values"), "Unit coordinates (0 .. 1 within the bounds) of parameter values.")
      .def(
          "to_values",
          [](const Calibration& c, const Vector& u) {
            return Array(
                c.objective().parameters().Values(VectorOf(u, c.objective().dimension(), "u")));
          },
          py::arg("u"), "Parameter values of unit coordinates (clamped to [0, 1]).")
      .def(
          "evaluate",
          [](const Calibration& c, const Vector& values) {
            const Eigen::VectorXd v = VectorOf(values, c.objective().dimension(), "values");
            return EvaluateUnit(c, UnitOfValues(c, v));
          },
          py::arg("values"),
          "The objective at parameter values (in their units): a dict with 'value' (what the "
          "optimiser minimises), 'data', 'prior', 'feasible', 'kind_scores', 'residuals', ... "
          "Values outside the bounds are infeasible (a finite penalty, no rocks run).")
      .def(
          "evaluate_unit",
          [](const Calibration& c, const Vector& u) {
            return EvaluateUnit(c, VectorOf(u, c.objective().dimension(), "u"));
          },
          py::arg("u"),
          "The objective at unit coordinates, as talus calibrate's optimisers call it (history.csv "
          "lists the values of these points).")
      .def(
          "ground_table",
          [](const Calibration& c, const Vector& values) {
            const Eigen::VectorXd u =
                UnitOfValues(c, VectorOf(values, c.objective().dimension(), "values"));
            return FromJson(io::GroundTableJson(c.objective().GroundOf(u)));
          },
          py::arg("values"), "The ground table these parameter values make, as Scene.ground.")
      .def(
          "uncertainty",
          [](const Calibration& c, const Vector& values, const py::object& fd_step) {
            return UncertaintyAt(
                c, UnitOfValues(c, VectorOf(values, c.objective().dimension(), "values")), fd_step);
          },
          py::arg("values"), py::arg("fd_step") = py::none(),
          "The sandwich covariance at parameter values (an optimum found with SciPy, say), as "
          "talus calibrate estimates it at its own: a dict with calibration.json's 'uncertainty' "
          "keys ('standard_error', 'covariance', 'correlation', 'identified', 'note', ...; no "
          "'bootstrap' or 'seeds') and 'report', the text talus calibrate prints. fd_step: the "
          "central-difference step in unit coordinates; None takes the file's [uncertainty] "
          "fd_step, else chooses it at the point by the fit's rule. It runs 2 n + 1 evaluations "
          "and more (the step's choice, a rank-deficient J^T J's profiles).")
      .def(
          "uncertainty_unit",
          [](const Calibration& c, const Vector& u, const py::object& fd_step) {
            return UncertaintyAt(c, VectorOf(u, c.objective().dimension(), "u"), fd_step);
          },
          py::arg("u"), py::arg("fd_step") = py::none(),
          "uncertainty() at unit coordinates, as calibration.json's optimiser starts list them.")
      .def("run", &Run, py::arg("progress") = py::none(), py::arg("max_evaluations") = py::none(),
           "Runs the calibration the file describes through the call talus calibrate makes (the "
           "fit, then the measurements at the optimum, the held-out runs and folds asked for at "
           "load). Returns {'calibration': what calibration.json holds, 'ground_table_toml', "
           "'history_csv', 'warnings'} (and 'shape_table_toml' with shape parameters). progress: "
           "a callable taking each stage's text; max_evaluations overrides the file's budget.");
}

}  // namespace talus::python
