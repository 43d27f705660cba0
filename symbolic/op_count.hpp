// Operation counts of an equation list as the emitter writes it: every right-hand side and output
// expression counted as a tree, each trigonometric abbreviation (S3, C3) once.
#pragma once

#include <cstdint>

#include "symbolic/equation_list.hpp"

namespace dydp::symbolic {

struct OpCount {
  std::uint64_t add = 0;   // additions and subtractions
  std::uint64_t mul = 0;   // multiplications (a small integer power x^n counts n-1)
  std::uint64_t div = 0;   // divisions
  std::uint64_t call = 0;  // sin, cos, tan, atan2, sqrt, exp, log, pow, abs, sign, min, max, select
  std::uint64_t total() const;  // saturating sum
};

// Counts saturate at 2^64-1 (an in-extenso expansion can be astronomically large).
OpCount count_ops(const EquationList& list);

// Largest |n| for which x^n is written as n-1 multiplications rather than a call to std::pow.
inline constexpr int kMaxInlinePower = 4;

}  // namespace dydp::symbolic
