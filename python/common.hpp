#pragma once
// What the bindings of the Python module share: how C++ runs without the GIL and stops on
// Ctrl-C, and how results become Python objects.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Eigen/Core>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "common/error.hpp"

namespace talus::python {

namespace py = pybind11;

// Thrown on the calling thread by a progress callback when Python has a signal pending (Ctrl-C):
// the run stops, and the binding raises the pending Python exception (KeyboardInterrupt).
struct PythonSignal {};

// A progress callback for runs without the GIL: every call (at most every 0.2 s) takes the GIL
// briefly to let Python handle signals, and stops the run when a handler raised.
inline std::function<void(long, long)> SignalCheck() {
  return [](long, long) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw PythonSignal{};
  };
}

// Runs `work` with the GIL released; a run stopped by a signal raises Python's pending exception.
template <class Work>
auto WithoutGil(Work&& work) {
  try {
    py::gil_scoped_release release;
    return work();
  } catch (const PythonSignal&) {
    throw py::error_already_set();
  }
}

// Python's json.loads of a JSON text written by the io library (the CLI's own files' text).
inline py::object FromJson(const std::string& text) {
  return py::module_::import("json").attr("loads")(text);
}

inline py::array_t<double> Array(const std::vector<double>& values) {
  py::array_t<double> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

inline py::array_t<double> Array(const Eigen::VectorXd& values) {
  py::array_t<double> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.data(), values.data() + values.size(), out.mutable_data());
  return out;
}

// Rows of `columns` doubles each as a (rows, columns) array.
inline py::array_t<double> Matrix(const std::vector<double>& values, py::ssize_t columns) {
  py::array_t<double> out({static_cast<py::ssize_t>(values.size()) / columns, columns});
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

// A NumPy array of str from C++ strings.
inline py::object StringArray(const std::vector<std::string>& values) {
  return py::module_::import("numpy").attr("array")(py::cast(values), "str");
}

void BindScene(py::module_& m);
void BindFieldObs(py::module_& m);
void BindCalibration(py::module_& m);

}  // namespace talus::python
