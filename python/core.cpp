// talus._core: the compiled part of the Python module (docs/python.md). Errors of bad input are
// talus.InputError (a ValueError) with the message the command line prints after "talus <verb>: ".

#include "common/error.hpp"
#include "python/common.hpp"
#include "talus/version.hpp"

namespace talus::python {

PYBIND11_MODULE(_core, m) {
  m.doc() = "Talus: rockfall simulation with non-smooth contact mechanics (compiled core)";
  m.attr("__version__") = kVersion;
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError).doc() =
      "Bad input (a scene, event or calibration file, a parameter value): the message names the "
      "file, line and key, as the command line's does.";
  BindScene(m);
  BindFieldObs(m);
  BindCalibration(m);
}

}  // namespace talus::python
