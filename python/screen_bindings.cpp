// Screening studies in Python: dydp.screen() runs (or resumes) a study like `dydp screen`,
// recording every run in out/runs/, and returns the samples and the measures as numpy arrays.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>

#include "engine/studies/screen_study.hpp"
#include "python/bindings.hpp"

namespace py = pybind11;

namespace dydp::python {
namespace {

/// Samples [samples x parameter], psi [samples x objective], gradients [samples x objective x
/// parameter]; the measures [objective x parameter]; the nominal run apart.
struct ScreenArrays {
  std::vector<std::string> parameter_names, parameter_units, objective_names, objective_units;
  py::array_t<double> lower, upper, nominal, p, values, gradients, nominal_values, nominal_gradients;
  py::array_t<double> mean, variance, nu, normalised, total_index_bound, mean_gradient, local_normalised;
  py::array_t<int> rank;
  int recorded_before = 0;
};

ScreenArrays screen(const std::filesystem::path& path, const std::vector<std::string>& parameters, int samples,
                    const std::filesystem::path& out, const py::dict& overrides, bool resume, int threads,
                    bool estimate, bool adjoint) {
  engine::ScreenSpec spec;
  spec.scene = path.string();
  spec.overrides = overrides_from(overrides);
  spec.parameters = parameters;
  spec.samples = samples;
  spec.out = out.string();
  spec.resume = resume;
  spec.threads = threads;
  spec.estimate = estimate;
  spec.adjoint = adjoint;
  engine::ScreenResult r;
  {
    py::gil_scoped_release released;
    r = engine::screen(spec);
  }
  ScreenArrays a;
  const py::ssize_t P = static_cast<py::ssize_t>(r.ranges.size()), O = static_cast<py::ssize_t>(r.objectives.size()),
                    N = static_cast<py::ssize_t>(r.samples.size());
  for (const auto& g : r.ranges) a.parameter_names.push_back(g.name);
  a.parameter_units = r.units;
  a.objective_names = r.objectives;
  a.objective_units = r.objective_units;
  a.recorded_before = r.recorded_before;
  a.lower = py::array_t<double>(P), a.upper = py::array_t<double>(P), a.nominal = py::array_t<double>(P);
  for (py::ssize_t i = 0; i < P; ++i) {
    a.lower.mutable_at(i) = r.ranges[i].lower;
    a.upper.mutable_at(i) = r.ranges[i].upper;
    a.nominal.mutable_at(i) = r.ranges[i].nominal;
  }
  a.p = py::array_t<double>({N, P});
  a.values = py::array_t<double>({N, O});
  a.gradients = py::array_t<double>({N, O, P});
  for (py::ssize_t k = 0; k < N; ++k)
    for (py::ssize_t o = 0; o < O; ++o) {
      a.values.mutable_at(k, o) = r.samples[k].psi[o];
      for (py::ssize_t i = 0; i < P; ++i) {
        a.p.mutable_at(k, i) = r.samples[k].p[i];
        a.gradients.mutable_at(k, o, i) = r.samples[k].gradient[o][i];
      }
    }
  a.nominal_values = py::array_t<double>(O);
  a.nominal_gradients = py::array_t<double>({O, P});
  a.mean = py::array_t<double>(O), a.variance = py::array_t<double>(O);
  for (auto* m : {&a.nu, &a.normalised, &a.total_index_bound, &a.mean_gradient, &a.local_normalised})
    *m = py::array_t<double>({O, P});
  a.rank = py::array_t<int>({O, P});
  for (py::ssize_t o = 0; o < O; ++o) {
    const engine::ScreeningEstimate& e = r.estimates[o];
    a.nominal_values.mutable_at(o) = r.nominal.psi[o];
    a.mean.mutable_at(o) = e.mean;
    a.variance.mutable_at(o) = e.variance;
    for (py::ssize_t i = 0; i < P; ++i) {
      const engine::ParameterMeasure& m = e.parameters[i];
      a.nominal_gradients.mutable_at(o, i) = r.nominal.gradient[o][i];
      a.nu.mutable_at(o, i) = m.nu;
      a.normalised.mutable_at(o, i) = m.normalised;
      a.total_index_bound.mutable_at(o, i) = m.total_index_bound;
      a.mean_gradient.mutable_at(o, i) = m.mean_gradient;
      a.local_normalised.mutable_at(o, i) = m.local_normalised;
      a.rank.mutable_at(o, i) = m.rank;
    }
  }
  return a;
}

}  // namespace

void add_screen_bindings(py::module_& m) {
  py::class_<ScreenArrays>(m, "ScreenResult", "A screening study: samples, gradients and the measures per objective.")
      .def_readonly("parameter_names", &ScreenArrays::parameter_names)
      .def_readonly("parameter_units", &ScreenArrays::parameter_units)
      .def_readonly("objective_names", &ScreenArrays::objective_names)
      .def_readonly("objective_units", &ScreenArrays::objective_units)
      .def_readonly("lower", &ScreenArrays::lower, "range low ends, shape (parameters,)")
      .def_readonly("upper", &ScreenArrays::upper, "range high ends, shape (parameters,)")
      .def_readonly("nominal", &ScreenArrays::nominal, "the scene's values, shape (parameters,)")
      .def_readonly("p", &ScreenArrays::p, "the Sobol' points, shape (samples, parameters)")
      .def_readonly("values", &ScreenArrays::values, "psi, shape (samples, objectives)")
      .def_readonly("gradients", &ScreenArrays::gradients, "dpsi/dp, shape (samples, objectives, parameters)")
      .def_readonly("nominal_values", &ScreenArrays::nominal_values, "psi at the nominal point, shape (objectives,)")
      .def_readonly("nominal_gradients", &ScreenArrays::nominal_gradients, "shape (objectives, parameters)")
      .def_readonly("mean", &ScreenArrays::mean, "of psi over the samples, shape (objectives,)")
      .def_readonly("variance", &ScreenArrays::variance, "of psi over the samples (N - 1), shape (objectives,)")
      .def_readonly("nu", &ScreenArrays::nu, "E[(dpsi/dp_i)^2], shape (objectives, parameters)")
      .def_readonly("normalised", &ScreenArrays::normalised, "(b - a)^2 nu as a share, shape (objectives, parameters)")
      .def_readonly("total_index_bound", &ScreenArrays::total_index_bound,
                    "(b - a)^2 nu / (pi^2 Var psi) >= S_T, shape (objectives, parameters)")
      .def_readonly("mean_gradient", &ScreenArrays::mean_gradient, "E[dpsi/dp_i], shape (objectives, parameters)")
      .def_readonly("local_normalised", &ScreenArrays::local_normalised,
                    "(p / psi) dpsi/dp at the nominal point, shape (objectives, parameters)")
      .def_readonly("rank", &ScreenArrays::rank, "1: the largest share, shape (objectives, parameters)")
      .def_readonly("recorded_before", &ScreenArrays::recorded_before, "runs taken from out/runs/ (resume)")
      .def("__repr__", [](const ScreenArrays& a) {
        return "<dydp.ScreenResult: " + std::to_string(a.parameter_names.size()) + " parameters, " +
               std::to_string(a.p.shape(0)) + " samples, " + std::to_string(a.objective_names.size()) + " objectives>";
      });
  m.def("screen", &screen, py::arg("scene"), py::arg("parameters"), py::arg("samples"), py::arg("out"),
        py::arg("overrides") = py::dict(), py::arg("resume") = false, py::arg("threads") = 0,
        py::arg("estimate") = true, py::arg("adjoint") = false,
        "Screens scene parameters (or declared directions) over their ranges as dydp screen: `samples` Sobol' "
        "points and the nominal point, each run recorded in out/runs/; resume keeps those records. estimate: "
        "each run estimates its own error (--no-estimate when false); adjoint: the gradients by the adjoint "
        "method, one backward run per point whatever the number of parameters (--adjoint).");
}

}  // namespace dydp::python
