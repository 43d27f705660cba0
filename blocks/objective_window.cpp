#include "blocks/objective_window.hpp"

#include <optional>
#include <sstream>
#include <string>

namespace dydp::blocks {
namespace {

using engine::BlockCheck;
using engine::CheckInput;

struct Span {
  double from, to;
};

/// The window as written, or nothing when absent (the whole run). The factory has already
/// refused a malformed one.
std::optional<Span> window_of(const CheckInput& in) {
  const std::vector<std::string> items = in.settings->texts("window");
  if (items.size() == 1 && items[0].empty()) return std::nullopt;
  const std::vector<double> v = in.settings->numbers("window");
  if (v.size() != 2) return std::nullopt;
  return Span{v[0], v[1]};
}

std::string describe(const Span& w, const CheckInput& in) {
  std::ostringstream s;
  s << "window [" << w.from << ", " << w.to << "] s, run [" << in.t_start << ", " << in.t_stop << "] s";
  return s.str();
}

}  // namespace

std::vector<BlockCheck> window_checks() {
  return {
      {"window overlaps [time.start, time.stop]", "window", BlockCheck::Severity::error,
       [](const CheckInput& in) -> std::optional<std::string> {
         const auto w = window_of(in);
         if (!w || (w->from < in.t_stop && w->to > in.t_start)) return std::nullopt;
         return describe(*w, in) + ": the window lies outside the run, psi would be 0";
       }},
      {"window lies within [time.start, time.stop]", "window", BlockCheck::Severity::warning,
       [](const CheckInput& in) -> std::optional<std::string> {
         const auto w = window_of(in);
         if (!w || (w->from >= in.t_start && w->to <= in.t_stop)) return std::nullopt;
         return describe(*w, in) + ": psi covers only the part inside the run";
       }},
      {"window starts after the first tenth of the run (initial transient)", "window",
       BlockCheck::Severity::warning,
       [](const CheckInput& in) -> std::optional<std::string> {
         const auto w = window_of(in);
         const double settled = in.t_start + kTransientFraction * (in.t_stop - in.t_start);
         if (!w || w->from >= settled) return std::nullopt;
         std::ostringstream s;
         s << describe(*w, in) << ": starts before " << settled
           << " s, inside the initial transient (the first tenth of the run)";
         return s.str();
       }},
  };
}

}  // namespace dydp::blocks
