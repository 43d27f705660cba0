// --report: plots of every logged signal and its normalised sensitivities (gnuplot PNG) and a
// report.md that links them with the objectives and run figures.
#pragma once

#include <string>

#include "engine/analysis/run_result.hpp"
#include "engine/framework/diagram.hpp"
#include "engine/studies/screen_study.hpp"
#include "engine/studies/sweep.hpp"

namespace dydp::apps {

/// Writes DIR/report.md and DIR/plots/*.png (needs DIR/signals.csv, written before).
/// Without gnuplot on the PATH, report.md says so and no plot is made.
void write_report(const std::string& dir, const engine::Diagram& d, const engine::RunResult& r);

/// Writes DIR/report.md and DIR/plots/*.png for a sweep: psi and d(psi)/dp against p, the
/// finite-difference error against step, the sensitivity history as a surface over (t, p) and
/// the logged signals for several p.
void write_sweep_report(const std::string& dir, const std::string& scene,
                        const engine::SweepResult& r, double delta);

/// Writes DIR/report.md and DIR/plots/*.png for a screening study: per objective the ranking
/// (table and tornado chart) and psi and d(psi)/dp_i against p_i over the samples.
void write_screen_report(const std::string& dir, const std::string& scene, const engine::ScreenResult& r);

}  // namespace dydp::apps
