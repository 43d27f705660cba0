// The consistency rules of an objective's `window: [from, to]` against the run: it must overlap
// the run (else psi is 0 with zero sensitivities); warned when it reaches past the run or starts
// inside the initial transient (the first tenth of the run). Shared by every objective type.
#pragma once

#include <vector>

#include "engine/framework/block_check.hpp"

namespace dydp::blocks {

/// Fraction of the run counted as its initial transient: a window starting before
/// t_start + kTransientFraction (t_stop - t_start) is warned about.
inline constexpr double kTransientFraction = 0.1;

std::vector<engine::BlockCheck> window_checks();

}  // namespace dydp::blocks
