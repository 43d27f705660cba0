// The interpreter: evaluates any equation list numerically, for tests and as a reference for the
// emitted code. The list is flattened once into a tape of instructions (one per distinct
// expression node); evaluation is templated on the scalar so tests can complex-step it.
#pragma once

#include <complex>
#include <cstdint>
#include <span>
#include <vector>

#include "symbolic/equation_list.hpp"

namespace dydp::symbolic {

class Tape {
 public:
  explicit Tape(const EquationList& list);

  // Evaluates the list. `arrays[a]` points at the values of the context's array a (inputs,
  // parameters, seeds); arrays the list does not read may be null. Writes every output to `out`.
  // For non-analytic operations (abs, sign, min, max, select) branch decisions use the real
  // part, so a complex step through them differentiates the branch taken.
  template <class T>
  void evaluate(std::span<const T* const> arrays, T* out) const;

  std::size_t output_count() const { return output_slots_.size(); }
  std::size_t instruction_count() const { return instructions_.size(); }

 private:
  struct Instruction {
    Op op;
    std::int32_t integer_exponent;  // Pow with a small integer constant exponent, else 0
    bool integer_power;
    std::uint32_t destination;
    std::uint32_t first_argument;   // into arguments_; for loads: the array
    std::uint32_t argument_count;   // for loads: the element index
  };
  static constexpr Op kLoad = Op::Symbol;

  std::vector<Instruction> instructions_;
  std::vector<std::uint32_t> arguments_;
  std::vector<std::pair<std::uint32_t, double>> constants_;
  std::vector<std::uint32_t> output_slots_;
  std::uint32_t slot_count_ = 0;
};

extern template void Tape::evaluate<double>(std::span<const double* const>, double*) const;
extern template void Tape::evaluate<std::complex<double>>(
    std::span<const std::complex<double>* const>, std::complex<double>*) const;

}  // namespace dydp::symbolic
