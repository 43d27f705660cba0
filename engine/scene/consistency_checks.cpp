#include "engine/scene/consistency_checks.hpp"

#include <algorithm>
#include <utility>

#include "engine/framework/errors.hpp"

namespace dydp::engine {
namespace {

/// Where the field a check names was written (file, line): a parameter's value, a setting,
/// else the block. `file`: the scene's, for a block written in it.
std::pair<std::string, int> where_field(const std::string& file, const Node& n, const std::string& field) {
  const std::string& block_file = n.file.empty() ? file : n.file;
  const auto& params = n.type->parameters;
  const auto ps = std::find_if(params.begin(), params.end(),
                               [&](const ParamSpec& s) { return s.name == field; });
  if (ps != params.end()) {
    const size_t j = static_cast<size_t>(ps - params.begin());
    const int line = n.p_line[j];
    if (line <= 0) return {block_file, n.line};
    return {j < n.p_file.size() && !n.p_file[j].empty() ? n.p_file[j] : block_file, line};
  }
  if (!n.settings) return {block_file, n.line};
  return {n.settings->file(field), n.settings->line(field)};
}

}  // namespace

void check_block(const std::string& file, const Node& n, const std::vector<double>& p,
                 const TimeSpec& time, std::vector<std::string>* warnings) {
  if (!n.type || !n.settings) return;
  const CheckInput in{p.data(), n.settings.get(), n.block.get(), time.start, time.stop};
  for (const BlockCheck& check : n.type->checks) {
    const std::optional<std::string> why = check.broken(in);
    if (!why) continue;
    const auto [at_file, at_line] = where_field(file, n, check.field);
    const InputError e(at_file, at_line, n.name + "." + check.field, *why);
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
