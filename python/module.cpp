// The Python module `dydp`: the exceptions that carry bad input's file, line and field and a
// solver failure's time and block, then the scene, sweep and block bindings.
#include <pybind11/pybind11.h>

#include <cstdio>
#include <exception>

#include "engine/framework/errors.hpp"
#include "python/bindings.hpp"

namespace py = pybind11;

namespace dydp::python {

std::vector<std::pair<std::string, std::string>> overrides_from(const py::dict& overrides) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [key, value] : overrides) {
    const std::string name = py::str(key);
    if (py::isinstance<py::str>(value)) {
      out.emplace_back(name, value.cast<std::string>());
    } else if (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)) {
      char text[32];
      std::snprintf(text, sizeof text, "%.17g", value.cast<double>());
      out.emplace_back(name, text);
    } else {
      throw engine::InputError("overrides", 0, name, "expected a number or a string, got " +
                                                          std::string(py::str(value.get_type().attr("__name__"))));
    }
  }
  return out;
}

}  // namespace dydp::python

PYBIND11_MODULE(dydp, m) {
  m.doc() =
      "dydp: exact sensitivities of vehicle comfort and handling to design parameters.\n"
      "load() a scene, run() it: numpy arrays of signals and their sensitivities, objectives\n"
      "with their gradients, run statistics; sweep() a parameter; screen() many over their ranges; blocks() lists the library.";

  // Exception classes made here so that they carry attributes: InputError is a ValueError with
  // file, line and field; SolverError a RuntimeError with time and block.
  static py::handle input_error(PyErr_NewExceptionWithDoc(
      "dydp.InputError", "Bad input (scene, recorded table, argument): attributes file, line, field.",
      PyExc_ValueError, nullptr));
  static py::handle solver_error(PyErr_NewExceptionWithDoc(
      "dydp.SolverError", "The integration could not go on: attributes time [s] and block.",
      PyExc_RuntimeError, nullptr));
  m.attr("InputError") = input_error;
  m.attr("SolverError") = solver_error;
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const dydp::engine::InputError& e) {
      py::object error = input_error(e.what());
      error.attr("file") = e.file();
      error.attr("line") = e.line();
      error.attr("field") = e.field();
      PyErr_SetObject(input_error.ptr(), error.ptr());
    } catch (const dydp::engine::SolverError& e) {
      py::object error = solver_error(e.what());
      error.attr("time") = e.time();
      error.attr("block") = e.block();
      PyErr_SetObject(solver_error.ptr(), error.ptr());
    }
  });

  dydp::python::add_scene_bindings(m);
  dydp::python::add_sweep_bindings(m);
  dydp::python::add_screen_bindings(m);
  dydp::python::add_block_bindings(m);
}
