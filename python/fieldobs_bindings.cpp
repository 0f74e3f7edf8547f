// talus.Event: an event file (its scene and field observations) and its validation -- the rocks
// run and every observation scored (CRPS, energy score, PIT) by the call talus validate makes,
// returning what scores.json holds.

#include <memory>

#include "io/event_file.hpp"
#include "io/validate_event.hpp"
#include "io/validation_outputs.hpp"
#include "python/common.hpp"
#include "talus/version.hpp"

namespace talus::python {
namespace {

std::string PathText(const py::object& path) {
  return py::str(py::module_::import("os").attr("fspath")(path)).cast<std::string>();
}

py::dict Validate(const io::EventFile& event, int threads) {
  if (threads < 0) throw InputError("threads: " + std::to_string(threads) + " must be >= 0");
  io::EventValidationOptions options;
  options.threads = threads;
  options.progress = SignalCheck();
  const std::string scores = WithoutGil([&] {
    const io::EventValidation validation = io::ValidateEvent(event, options);
    return io::ScoresJson(event, validation.report, validation.run);
  });
  return FromJson(scores).cast<py::dict>();
}

}  // namespace

void BindFieldObs(py::module_& m) {
  py::class_<io::EventFile, std::shared_ptr<io::EventFile>>(
      m, "Event",
      "An event file (docs/validation.md): a scene and the field observations of its runs, "
      "loaded and checked as talus validate loads them.")
      .def_static(
          "load",
          [](const py::object& path) {
            const std::string text = PathText(path);
            return std::make_shared<io::EventFile>(WithoutGil([&] { return io::LoadEvent(text); }));
          },
          py::arg("path"), "Loads an event file; raises talus.InputError naming file, line and key.")
      .def_property_readonly(
          "scene",
          [](const std::shared_ptr<io::EventFile>& event) {
            // Shares the event: edits of the scene (ground, rocks, seed) are the event's.
            return std::shared_ptr<io::SceneFile>(event, &event->scene);
          },
          "The event's scene; editing it (set_ground, rocks, seed) edits what validate runs.")
      .def_readonly("path", &io::EventFile::path)
      .def_readonly("reference", &io::EventFile::reference)
      .def_readonly("not_scored", &io::EventFile::not_scored)
      .def_readonly("inputs", &io::EventFile::inputs)
      .def_property_readonly("observations",
                             [](const io::EventFile& e) {
                               py::dict d;
                               d["scalars"] = e.observations.scalars.size();
                               d["deposits"] = e.observations.deposits.size();
                               d["zones"] = e.observations.zones.size();
                               return d;
                             },
                             "How many observations of each sort the event holds.")
      .def("validate", &Validate, py::arg("threads") = 0,
           "Runs the event's scene (and the reference table's, when it differs) and scores every "
           "observation as talus validate does, with the GIL released; returns what scores.json "
           "holds, as a dict.");
}

}  // namespace talus::python
