// Running gnuplot for the reports: is it there, file-safe names, run a script.
#pragma once

#include <string>

namespace dydp::apps {

bool have_gnuplot();
/// Letters and digits kept, everything else '_'.
std::string file_safe(const std::string& name);
/// Writes the script to DIR/plots/NAME.gp and runs gnuplot on it; false (and a log in
/// DIR/plots/NAME.log) when gnuplot fails.
bool run_gnuplot(const std::string& dir, const std::string& name, const std::string& script);

}  // namespace dydp::apps
