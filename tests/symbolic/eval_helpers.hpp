// Evaluating lists of the random test model with the interpreter, in double and complex.
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>
#include <vector>

#include "symbolic/interpret.hpp"

namespace dydp::symbolic::testing {

// Values for every array of a context, indexed by ArrayId.
template <class T>
struct ArrayValues {
  std::vector<std::vector<T>> values;

  ArrayValues() = default;
  explicit ArrayValues(const Context& ctx) : values(ctx.array_count()) {
    for (ArrayId a = 0; a < ctx.array_count(); ++a) values[a].assign(ctx.array(a).elements.size(), T(0.0));
  }
  std::vector<const T*> pointers() const {
    std::vector<const T*> p;
    for (const auto& v : values) p.push_back(v.data());
    return p;
  }
};

template <class T>
std::vector<T> run(const Tape& tape, const ArrayValues<T>& arrays) {
  std::vector<T> out(tape.output_count());
  const auto pointers = arrays.pointers();
  tape.evaluate<T>(pointers, out.data());
  return out;
}

inline ArrayValues<std::complex<double>> to_complex(const ArrayValues<double>& a) {
  ArrayValues<std::complex<double>> c;
  for (const auto& v : a.values) c.values.emplace_back(v.begin(), v.end());
  return c;
}

// |a - b| within `relative` of the larger magnitude (or of 1 near zero).
inline bool close(double a, double b, double relative) {
  const double scale = std::max({std::fabs(a), std::fabs(b), 1e-3});
  return std::fabs(a - b) <= relative * scale;
}

}  // namespace dydp::symbolic::testing
