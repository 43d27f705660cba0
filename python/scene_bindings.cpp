// Scenes and runs in Python: load() a scene with parameter overrides, run() it with the GIL
// released and an optional progress callback, and get the recorded results as numpy arrays.
#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <filesystem>

#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "engine/analysis/cvodes_adjoint.hpp"
#include "engine/analysis/error_estimate.hpp"
#include "engine/analysis/run.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/framework/errors.hpp"
#include "engine/studies/initial_equilibrium.hpp"
#include "io/output_writer.hpp"
#include "python/bindings.hpp"

namespace py = pybind11;

namespace dydp::python {
namespace {

/// A loaded scene: the frozen diagram, run as often as asked. Runs of one scene take turns
/// (its blocks' instances are shared by them); scenes loaded apart run in parallel.
struct Scene {
  engine::Diagram diagram;
  std::vector<std::pair<std::string, std::string>> overrides;  ///< as loaded (a shadow run loads it again)
  std::unique_ptr<std::mutex> running = std::make_unique<std::mutex>();
};

/// A run's results with numpy arrays: t [n], signals [n x signal], sensitivities
/// [n x signal x direction]; objectives, their gradients and the run statistics as dicts.
struct RunArrays {
  py::array_t<double> t, signals, sensitivities;
  std::vector<std::string> signal_names, signal_units, sensitivity_names, sensitivity_units;
  py::dict objectives, stats;

  int signal_index(const std::string& name) const {
    for (size_t i = 0; i < signal_names.size(); ++i)
      if (signal_names[i] == name) return static_cast<int>(i);
    throw py::key_error("no logged signal '" + name + "'");
  }
  int direction_index(const std::string& name) const {
    for (size_t d = 0; d < sensitivity_names.size(); ++d)
      if (sensitivity_names[d] == name) return static_cast<int>(d);
    throw py::key_error("no sensitivity direction '" + name + "'");
  }
};

RunArrays arrays_of(const engine::Diagram& d, const engine::RunResult& r) {
  RunArrays a;
  const py::ssize_t n = static_cast<py::ssize_t>(r.t.size()), nsig = r.num_signals();
  // adjoint: the objectives' gradients only, no signal sensitivities (shape (n, signals, 0))
  const py::ssize_t ns = r.signal_sensitivities ? static_cast<py::ssize_t>(r.sensitivity_names.size()) : 0;
  a.t = py::array_t<double>(n);
  a.signals = py::array_t<double>({n, nsig});
  a.sensitivities = py::array_t<double>({n, nsig, ns});
  auto t = a.t.mutable_unchecked<1>();
  auto y = a.signals.mutable_unchecked<2>();
  auto dy = a.sensitivities.mutable_unchecked<3>();
  for (py::ssize_t k = 0; k < n; ++k) {
    t(k) = r.t[k];
    for (py::ssize_t i = 0; i < nsig; ++i) {
      y(k, i) = r.value(static_cast<int>(k), static_cast<int>(i));
      for (py::ssize_t dir = 0; dir < ns; ++dir)
        dy(k, i, dir) = r.tangent(static_cast<int>(k), static_cast<int>(dir), static_cast<int>(i));
    }
  }
  a.signal_names = r.signal_names;
  for (const auto& s : d.logged) a.signal_units.push_back(d.signal_unit(s.offset));
  a.sensitivity_names = r.sensitivity_names;
  for (const auto& p : r.sensitivity_names) a.sensitivity_units.push_back(d.parameters[d.find_parameter(p)].unit);
  for (const auto& o : r.objectives) {
    py::dict gradient, gradient_units;
    for (size_t k = 0; k < r.sensitivity_names.size(); ++k) {
      gradient[py::str(r.sensitivity_names[k])] = o.sensitivity[k];
      gradient_units[py::str(r.sensitivity_names[k])] = engine::unit_per(o.unit, a.sensitivity_units[k]);
    }
    py::dict entry;
    entry["value"] = o.value;
    entry["unit"] = o.unit;
    entry["gradient"] = gradient;
    entry["gradient_units"] = gradient_units;
    a.objectives[py::str(o.name)] = entry;
  }
  // The same statistics, under the same keys, as run.json.
  a.stats = py::module_::import("json").attr("loads")(io::run_json(d, r));
  return a;
}

/// The scene loaded again for a shadow run: its overrides, then its parameters, solver and
/// sensitivities as they stand (a diagram's blocks are not shared between threads).
engine::Diagram shadow_of(const Scene& scene) {
  const engine::Diagram& d = scene.diagram;
  engine::Diagram shadow = engine::load_scene(d.file, scene.overrides);
  for (size_t k = 0; k < d.parameters.size(); ++k)
    if (shadow.parameters[k].value != d.parameters[k].value)
      shadow.set_parameter(static_cast<int>(k), d.parameters[k].value, /*check_range=*/false);
  shadow.solver = d.solver;
  shadow.set_sensitivities(d.sensitivities);
  return shadow;
}

RunArrays run_scene(Scene& scene, bool sensitivities, const py::object& progress, bool estimate, bool adjoint) {
  engine::RunOptions options;
  options.sensitivities = sensitivities;
  options.adjoint = adjoint;
  if (adjoint && !sensitivities)
    throw engine::InputError("adjoint", 0, "sensitivities", "adjoint=True computes sensitivities: drop sensitivities=False");
  if (!progress.is_none()) {
    if (!PyCallable_Check(progress.ptr())) throw py::type_error("progress must be callable: progress(t)");
    options.progress = [&progress](double t) {
      py::gil_scoped_acquire gil;
      progress(t);  // an exception raised here ends the run and reaches the caller
    };
  }
  engine::RunResult r;
  {
    py::gil_scoped_release released;
    const std::lock_guard<std::mutex> turn(*scene.running);
    // adjoint: every declared parameter and direction for this run, the scene's own list after it
    const std::vector<int> declared = scene.diagram.sensitivities;
    struct Restore {
      engine::Diagram& d;
      const std::vector<int>& directions;
      ~Restore() { d.set_sensitivities(directions); }
    };
    std::optional<Restore> restore;
    if (adjoint) {
      engine::check_adjoint_possible(scene.diagram);
      restore.emplace(Restore{scene.diagram, declared});
      scene.diagram.set_sensitivities(engine::differentiable_parameters(scene.diagram));
    }
    engine::start_at_equilibrium(scene.diagram);  // `initial: equilibrium`: its start first (the shadow's too)
    if (estimate) {
      engine::Diagram shadow = shadow_of(scene);
      r = engine::run_with_error_estimate(scene.diagram, shadow, options);
    } else {
      r = engine::run(scene.diagram, options);
    }
  }
  return arrays_of(scene.diagram, r);
}

std::unique_ptr<Scene> load(const std::filesystem::path& path, const py::dict& overrides) {
  const auto sets = overrides_from(overrides);
  py::gil_scoped_release released;
  try {
    auto scene = std::make_unique<Scene>();
    scene->diagram = engine::load_scene(path.string(), sets);
    scene->overrides = sets;
    return scene;
  } catch (const engine::InputError& e) {
    // The loader names an override by its command-line option; here it came from `overrides`.
    const std::string option = "--set: " + e.field() + ": ", what = e.what();
    if (e.file() != "--set" || what.rfind(option, 0) != 0) throw;
    throw engine::InputError("overrides", e.line(), e.field(), what.substr(option.size()));
  }
}

py::dict parameters_of(const engine::Diagram& d) {
  py::dict out;
  for (const auto& p : d.parameters) {
    py::dict entry;
    entry["value"] = p.value;
    entry["unit"] = p.unit;
    entry["range"] = py::make_tuple(p.lower, p.upper);
    out[py::str(p.name)] = entry;
  }
  return out;
}

}  // namespace

void add_scene_bindings(py::module_& m) {
  py::class_<RunArrays>(m, "RunResult", "A run's recorded signals, sensitivities, objectives and statistics.")
      .def_readonly("t", &RunArrays::t, "output times [s], shape (n,)")
      .def_readonly("signals", &RunArrays::signals, "logged signals, shape (n, signals)")
      .def_readonly("sensitivities", &RunArrays::sensitivities,
                    "d(signal)/d(parameter), shape (n, signals, directions)")
      .def_readonly("signal_names", &RunArrays::signal_names)
      .def_readonly("signal_units", &RunArrays::signal_units)
      .def_readonly("sensitivity_names", &RunArrays::sensitivity_names, "the directions (scene parameters)")
      .def_readonly("sensitivity_units", &RunArrays::sensitivity_units, "units of the direction parameters")
      .def_readonly("objectives", &RunArrays::objectives,
                    "{name: {value, unit, gradient: {parameter: d(psi)/dp}, gradient_units}}")
      .def_readonly("stats", &RunArrays::stats, "run statistics, the keys of run.json")
      .def(
          "signal", [](const RunArrays& a, const std::string& name) {
            return py::object(a.signals[py::make_tuple(py::slice(py::none(), py::none(), py::none()), a.signal_index(name))]);
          },
          py::arg("name"), "one logged signal against t, shape (n,)")
      .def(
          "sensitivity",
          [](const RunArrays& a, const std::string& signal, const std::string& parameter) {
            return py::object(a.sensitivities[py::make_tuple(py::slice(py::none(), py::none(), py::none()),
                                                  a.signal_index(signal), a.direction_index(parameter))]);
          },
          py::arg("signal"), py::arg("parameter"), "d(signal)/d(parameter) against t, shape (n,)")
      .def("__repr__", [](const RunArrays& a) {
        return "<dydp.RunResult: " + std::to_string(a.t.size()) + " samples, " +
               std::to_string(a.signal_names.size()) + " signals, " + std::to_string(a.sensitivity_names.size()) +
               " directions, " + std::to_string(a.objectives.size()) + " objectives>";
      });

  py::class_<Scene>(m, "Scene", "A loaded, validated scene; run() it as often as needed.")
      .def_property_readonly("name", [](const Scene& s) { return s.diagram.scene_name; })
      .def_property_readonly("file", [](const Scene& s) { return s.diagram.file; })
      .def_property_readonly("parameters", [](const Scene& s) { return parameters_of(s.diagram); },
                             "{name: {value, unit, range: (low, high)}}")
      .def_property_readonly("sensitivities", [](const Scene& s) {
        std::vector<std::string> names;
        for (int p : s.diagram.sensitivities) names.push_back(s.diagram.parameters[p].name);
        return names;
      }, "the sensitivity directions")
      .def_property_readonly("outputs", [](const Scene& s) {
        std::vector<std::string> names;
        for (const auto& l : s.diagram.logged) names.push_back(l.name);
        return names;
      }, "the logged signals")
      .def_property_readonly("warnings", [](const Scene& s) { return s.diagram.warnings; })
      .def_property_readonly("pruned", [](const Scene& s) { return s.diagram.pruned; },
                             "blocks no requested output needs")
      .def(
          "set_parameter",
          [](Scene& s, const std::string& name, double value) {
            const int index = s.diagram.find_parameter(name);
            if (index < 0) throw engine::InputError(s.diagram.file, 0, name, "no scene parameter of that name");
            // Waits for a run of this scene to end without holding the GIL (its progress
            // callback needs it).
            py::gil_scoped_release released;
            const std::lock_guard<std::mutex> turn(*s.running);
            s.diagram.set_parameter(index, value);
          },
          py::arg("name"), py::arg("value"), "sets a scene parameter (checked against its range)")
      .def("run", &run_scene, py::arg("sensitivities") = true, py::arg("progress") = py::none(),
           py::arg("estimate") = true, py::arg("adjoint") = false,
           "Runs the scene (the GIL released); progress(t) is called at every output time; estimate: "
           "a shadow run beside it estimates its error (stats['error_estimate'], as run.json); adjoint: "
           "the objectives' gradients for every declared parameter and direction by the adjoint method "
           "(one backward run; no signal sensitivities; stats['adjoint'] as run.json). "
           "Runs of one scene take turns; load a scene per thread to run in parallel.")
      .def("__repr__", [](const Scene& s) { return "<dydp.Scene " + s.diagram.scene_name + " from " + s.diagram.file + ">"; });

  m.def("load", &load, py::arg("scene"), py::arg("overrides") = py::dict(),
        "Loads a scene file; overrides {NAME: VALUE} set scene parameters (as --set). "
        "Bad input raises dydp.InputError with file, line and field.");
  m.def(
      "run",
      [](const std::filesystem::path& path, const py::dict& overrides, bool sensitivities, const py::object& progress,
         bool estimate, bool adjoint) {
        const std::unique_ptr<Scene> scene = load(path, overrides);
        return run_scene(*scene, sensitivities, progress, estimate, adjoint);
      },
      py::arg("scene"), py::arg("overrides") = py::dict(), py::arg("sensitivities") = true,
      py::arg("progress") = py::none(), py::arg("estimate") = true, py::arg("adjoint") = false,
      "load(scene, overrides).run(sensitivities, progress, estimate, adjoint)");
}

}  // namespace dydp::python
