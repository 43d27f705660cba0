// Sweeps in Python: psi and d(psi)/dp at each point of a parameter range (the runs spread over
// the cores, the GIL released), optionally central differences, as numpy arrays.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>

#include "engine/studies/sweep.hpp"
#include "python/bindings.hpp"

namespace py = pybind11;

namespace dydp::python {
namespace {

/// p [points]; values and gradients [points x objective]; fd [points x step x objective].
struct SweepArrays {
  std::string parameter, unit;
  std::vector<std::string> objective_names, objective_units;
  std::vector<double> fd_steps;
  py::array_t<double> p, values, gradients, fd, cpu_seconds, error_signals, error_sensitivities;
};

SweepArrays sweep(const std::filesystem::path& path, const std::string& parameter, double low, double high, int points,
                  const py::dict& overrides, const std::vector<double>& fd_steps, int threads, bool estimate) {
  engine::SweepSpec spec;
  spec.scene = path.string();
  spec.overrides = overrides_from(overrides);
  spec.parameter = parameter;
  spec.low = low, spec.high = high, spec.points = points;
  spec.fd_steps = fd_steps;
  spec.threads = threads;
  spec.estimate = estimate;
  engine::SweepResult r;
  {
    py::gil_scoped_release released;
    r = engine::sweep(spec);
  }
  SweepArrays a;
  a.parameter = r.parameter, a.unit = r.unit;
  a.objective_names = r.objectives, a.objective_units = r.objective_units;
  a.fd_steps = r.fd_steps;
  const py::ssize_t n = static_cast<py::ssize_t>(r.points.size()), no = static_cast<py::ssize_t>(r.objectives.size());
  const py::ssize_t nh = static_cast<py::ssize_t>(r.fd_steps.size());
  a.p = py::array_t<double>(n);
  a.cpu_seconds = py::array_t<double>(n);
  a.error_signals = py::array_t<double>(n);
  a.error_sensitivities = py::array_t<double>(n);
  a.values = py::array_t<double>({n, no});
  a.gradients = py::array_t<double>({n, no});
  a.fd = py::array_t<double>({n, nh, no});
  auto p = a.p.mutable_unchecked<1>();
  auto cpu = a.cpu_seconds.mutable_unchecked<1>();
  auto es = a.error_signals.mutable_unchecked<1>();
  auto ed = a.error_sensitivities.mutable_unchecked<1>();
  auto psi = a.values.mutable_unchecked<2>();
  auto dpsi = a.gradients.mutable_unchecked<2>();
  auto fd = a.fd.mutable_unchecked<3>();
  for (py::ssize_t k = 0; k < n; ++k) {
    const engine::SweepPoint& pt = r.points[k];
    p(k) = pt.p;
    cpu(k) = pt.stats.cpu_seconds;
    const engine::ErrorEstimate& e = pt.stats.error_estimate;
    es(k) = e.estimated ? e.signal_error : std::nan("");
    ed(k) = e.estimated ? e.sensitivity_error : std::nan("");
    for (py::ssize_t o = 0; o < no; ++o) {
      psi(k, o) = pt.psi[o];
      dpsi(k, o) = pt.dpsi[o];
      for (py::ssize_t s = 0; s < nh; ++s) fd(k, s, o) = pt.fd[s][o];
    }
  }
  return a;
}

}  // namespace

void add_sweep_bindings(py::module_& m) {
  py::class_<SweepArrays>(m, "SweepResult", "psi and d(psi)/dp of every objective over a parameter range.")
      .def_readonly("parameter", &SweepArrays::parameter)
      .def_readonly("unit", &SweepArrays::unit, "of the swept parameter")
      .def_readonly("objective_names", &SweepArrays::objective_names)
      .def_readonly("objective_units", &SweepArrays::objective_units)
      .def_readonly("fd_steps", &SweepArrays::fd_steps)
      .def_readonly("p", &SweepArrays::p, "the parameter's values, shape (points,)")
      .def_readonly("values", &SweepArrays::values, "psi, shape (points, objectives)")
      .def_readonly("gradients", &SweepArrays::gradients, "d(psi)/dp, shape (points, objectives)")
      .def_readonly("fd", &SweepArrays::fd, "central differences, shape (points, fd_steps, objectives)")
      .def_readonly("cpu_seconds", &SweepArrays::cpu_seconds, "per point, shape (points,)")
      .def_readonly("error_estimate_signals", &SweepArrays::error_signals,
                    "each point's estimate of its own error in the logged signals (NaN: not estimated), shape (points,)")
      .def_readonly("error_estimate_sensitivities", &SweepArrays::error_sensitivities,
                    "the same for their sensitivity columns, shape (points,)")
      .def("__repr__", [](const SweepArrays& a) {
        return "<dydp.SweepResult: " + a.parameter + " at " + std::to_string(a.p.size()) + " points, " +
               std::to_string(a.objective_names.size()) + " objectives>";
      });
  m.def("sweep", &sweep, py::arg("scene"), py::arg("parameter"), py::arg("low"), py::arg("high"), py::arg("points"),
        py::arg("overrides") = py::dict(), py::arg("fd_steps") = std::vector<double>{}, py::arg("threads") = 0,
        py::arg("estimate") = true,
        "Sweeps a scene parameter over [low, high] at `points` points (as dydp sweep --range LO:HI:N); "
        "fd_steps adds central differences at those absolute steps; threads 0: one per core; estimate: each "
        "point's run estimates its own error by a shadow run (False: none, half the CPU).");
}

}  // namespace dydp::python
