// Consistency checks a block type declares beside its parameters: relations between its
// values (a rod narrower than its piston, a noise band's low end below its high end) and
// between its values and the run (an objective window inside the run). The scene loader runs
// them on every block, `dydp blocks` prints their rules.
#pragma once

#include <functional>
#include <optional>
#include <string>

#include "engine/framework/block_settings.hpp"

namespace dydp::engine {

class Block;

/// What a check sees: the block's parameter values (in ParamSpec order), its settings, the
/// instance made from them, and the run's time span [s].
struct CheckInput {
  const double* p = nullptr;
  const BlockSettings* settings = nullptr;
  const Block* block = nullptr;
  double t_start = 0.0;
  double t_stop = 0.0;
};

struct BlockCheck {
  enum class Severity {
    error,    ///< the values make no sense: the scene is refused (exit 2)
    warning,  ///< legal but probably unintended: printed and recorded in run.json `warnings`
  };
  std::string rule;   ///< the rule as `dydp blocks` prints it: "rod_diameter < piston_diameter"
  std::string field;  ///< the parameter or setting a broken rule is reported at
  Severity severity = Severity::error;
  /// Why the rule is broken for these values, or nothing when it holds.
  std::function<std::optional<std::string>(const CheckInput&)> broken;
};

}  // namespace dydp::engine
