// A scene that starts at its static equilibrium (`initial: equilibrium`, docs/scenes.md): the
// equilibrium at time.start with the inputs held there (and `initial.hold`), found by
// engine/linear/equilibrium.hpp, made the diagram's start state with dx*/dp as the initial
// sensitivities, so that a run's d(signal)/dp is that of a run starting at the equilibrium of
// the perturbed parameters. engine/analysis cannot include engine/linear (docs/architecture.md):
// every caller of run() for such a scene goes through here (the commands, the studies, the GUI's
// worker, the Python module).
#pragma once

#include <functional>
#include <optional>

#include "engine/analysis/run.hpp"
#include "engine/linear/equilibrium.hpp"

namespace dydp::engine {

/// For a scene with `initial: equilibrium` whose start is not current (never computed, or the
/// parameters or time.start changed since): finds the equilibrium and sets d.start; returns it.
/// Nothing for other scenes (nullopt). A scene with no equilibrium in reach is an InputError at
/// the line of `initial:` carrying the Newton's residual.
std::optional<Equilibrium> start_at_equilibrium(Diagram& d);

/// The same at time t with `held` (signal offset, value) held besides the scene's own
/// `initial.hold`, computed whether or not d.start is current: an FMU's start, its inputs held
/// at the importer's values (fmi/fmu_model.cpp). Nothing for a scene without `initial:
/// equilibrium`.
std::optional<Equilibrium> start_at_equilibrium(Diagram& d, double t, const std::vector<std::pair<int, double>>& held);

/// start_at_equilibrium(d), then run(d, options).
RunResult run_from_initial(Diagram& d, const RunOptions& options = {});

/// A study's run of the diagram `make` builds (a point of a sweep or a screening study): from
/// its initial state or equilibrium, and with `estimate` its error estimated by a shadow run of
/// a second diagram from `make` (engine/analysis/error_estimate.hpp) that starts where it does.
/// With `adjoint`, the objectives' gradients by the adjoint method (RunOptions::adjoint).
RunResult run_study_point(const std::function<Diagram()>& make, bool estimate, bool adjoint = false);

}  // namespace dydp::engine
