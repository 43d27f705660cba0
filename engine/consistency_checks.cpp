#include "engine/consistency_checks.hpp"

#include <algorithm>

#include "engine/errors.hpp"

namespace dydp::engine {
namespace {

/// Where the field a check names was written: a parameter's value, a setting, else the block.
int line_of_field(const Node& n, const std::string& field) {
  const auto& params = n.type->parameters;
  const auto ps = std::find_if(params.begin(), params.end(),
                               [&](const ParamSpec& s) { return s.name == field; });
  if (ps != params.end()) {
    const int line = n.p_line[ps - params.begin()];
    return line > 0 ? line : n.line;
  }
  return n.settings ? n.settings->line(field) : n.line;
}

}  // namespace

void check_block(const std::string& file, const Node& n, const std::vector<double>& p,
                 const TimeSpec& time, std::vector<std::string>* warnings) {
  if (!n.type || !n.settings) return;
  const CheckInput in{p.data(), n.settings.get(), n.block.get(), time.start, time.stop};
  for (const BlockCheck& check : n.type->checks) {
    const std::optional<std::string> why = check.broken(in);
    if (!why) continue;
    const InputError e(file, line_of_field(n, check.field), n.name + "." + check.field, *why);
    if (check.severity == BlockCheck::Severity::error) throw e;
    if (warnings) warnings->push_back(e.what());
  }
}

std::vector<std::string> check_rules(const BlockType& type) {
  std::vector<std::string> rules;
  for (const BlockCheck& check : type.checks)
    rules.push_back(check.rule +
                    (check.severity == BlockCheck::Severity::warning ? " (warning)" : ""));
  return rules;
}

}  // namespace dydp::engine
