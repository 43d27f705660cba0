// Flattening an equation list into a tape, and evaluating the tape.
#include "symbolic/interpret.hpp"

#include "symbolic/dag_walk.hpp"

#include <cmath>
#include <stdexcept>

namespace dydp::symbolic {
namespace {

constexpr std::uint32_t kNone = 0xFFFFFFFFu;

double real_part(double x) { return x; }
double real_part(const std::complex<double>& x) { return x.real(); }

double atan2_of(double y, double x) { return std::atan2(y, x); }
// Complex-step atan2: value from the real parts, first-order imaginary part from the derivative
// (x dy - y dx) / (x^2 + y^2); std has no complex atan2.
std::complex<double> atan2_of(const std::complex<double>& y, const std::complex<double>& x) {
  const double yr = y.real(), xr = x.real();
  return {std::atan2(yr, xr), (xr * y.imag() - yr * x.imag()) / (xr * xr + yr * yr)};
}

template <class T>
T integer_power(T x, int n) {
  const bool inverse = n < 0;
  unsigned k = static_cast<unsigned>(inverse ? -n : n);
  T result(1.0), base = x;
  while (k) {
    if (k & 1u) result *= base;
    base *= base;
    k >>= 1u;
  }
  return inverse ? T(1.0) / result : result;
}

template <class T>
T sign_of(const T& x) {
  const double r = real_part(x);
  return T(r > 0.0 ? 1.0 : (r < 0.0 ? -1.0 : 0.0));
}

}  // namespace

Tape::Tape(const EquationList& list) {
  const Context& ctx = list.context();
  std::vector<std::uint32_t> slot_of(ctx.size(), kNone);
  std::vector<NodeId> stack;

  // Post-order flattening of one expression; nodes met before reuse their slot.
  auto compile = [&](NodeId root) -> std::uint32_t {
    walk_post_order(ctx, root, stack, [&](NodeId n) { return slot_of[n] != kNone; }, [&](NodeId n) {
      const Op op = ctx.op(n);
      if (op == Op::Constant) {
        slot_of[n] = slot_count_++;
        constants_.emplace_back(slot_of[n], ctx.value(n));
        return;
      }
      if (op == Op::Symbol) {
        const Symbol& s = ctx.symbol(n);
        if (s.kind == SymbolKind::Aux) {
          throw std::invalid_argument("symbolic: auxiliary '" + s.name + "' is read before it is assigned");
        }
        slot_of[n] = slot_count_++;
        instructions_.push_back(Instruction{kLoad, 0, false, slot_of[n], s.array, s.index});
        return;
      }
      Instruction ins{op, 0, false, slot_count_++, static_cast<std::uint32_t>(arguments_.size()),
                      static_cast<std::uint32_t>(ctx.children(n).size())};
      for (NodeId c : ctx.children(n)) arguments_.push_back(slot_of[c]);
      if (op == Op::Pow && ctx.op(ctx.children(n)[1]) == Op::Constant) {
        const double e = ctx.value(ctx.children(n)[1]);
        if (e == std::nearbyint(e) && std::fabs(e) <= 64.0) {
          ins.integer_power = true;
          ins.integer_exponent = static_cast<std::int32_t>(e);
        }
      }
      slot_of[n] = ins.destination;
      instructions_.push_back(ins);
    });
    return slot_of[root];
  };

  for (const Assignment& a : list.assignments()) {
    if (slot_of[a.target] != kNone) {
      throw std::invalid_argument("symbolic: auxiliary '" + ctx.symbol(a.target).name + "' assigned twice");
    }
    slot_of[a.target] = compile(a.value);
  }
  for (const Output& o : list.outputs()) output_slots_.push_back(compile(o.value));
}

template <class T>
void Tape::evaluate(std::span<const T* const> arrays, T* out) const {
  std::vector<T> r(slot_count_);
  for (const auto& [slot, v] : constants_) r[slot] = T(v);
  for (const Instruction& ins : instructions_) {
    const std::uint32_t* a = arguments_.data() + ins.first_argument;
    T& dst = r[ins.destination];
    switch (ins.op) {
      case kLoad: {
        if (ins.first_argument >= arrays.size() || arrays[ins.first_argument] == nullptr) {
          throw std::invalid_argument("symbolic: Tape::evaluate: an array the list reads is missing");
        }
        dst = arrays[ins.first_argument][ins.argument_count];
        break;
      }
      case Op::Add: {
        T s = r[a[0]];
        for (std::uint32_t i = 1; i < ins.argument_count; ++i) s += r[a[i]];
        dst = s;
        break;
      }
      case Op::Mul: {
        T p = r[a[0]];
        for (std::uint32_t i = 1; i < ins.argument_count; ++i) p *= r[a[i]];
        dst = p;
        break;
      }
      case Op::Neg: dst = -r[a[0]]; break;
      case Op::Div: dst = r[a[0]] / r[a[1]]; break;
      case Op::Pow:
        dst = ins.integer_power ? integer_power(r[a[0]], ins.integer_exponent)
                                : T(std::pow(r[a[0]], r[a[1]]));
        break;
      case Op::Sin: dst = std::sin(r[a[0]]); break;
      case Op::Cos: dst = std::cos(r[a[0]]); break;
      case Op::Tan: dst = std::tan(r[a[0]]); break;
      case Op::Atan2: dst = atan2_of(r[a[0]], r[a[1]]); break;
      case Op::Sqrt: dst = std::sqrt(r[a[0]]); break;
      case Op::Exp: dst = std::exp(r[a[0]]); break;
      case Op::Log: dst = std::log(r[a[0]]); break;
      case Op::Abs: dst = r[a[0]] * sign_of(r[a[0]]); break;
      case Op::Sign: dst = sign_of(r[a[0]]); break;
      case Op::Min: dst = real_part(r[a[1]]) - real_part(r[a[0]]) > 0.0 ? r[a[0]] : r[a[1]]; break;
      case Op::Max: dst = real_part(r[a[0]]) - real_part(r[a[1]]) > 0.0 ? r[a[0]] : r[a[1]]; break;
      case Op::Select: dst = real_part(r[a[0]]) > 0.0 ? r[a[1]] : r[a[2]]; break;
      case Op::Constant: break;
    }
  }
  for (std::size_t i = 0; i < output_slots_.size(); ++i) out[i] = r[output_slots_[i]];
}

template void Tape::evaluate<double>(std::span<const double* const>, double*) const;
template void Tape::evaluate<std::complex<double>>(std::span<const std::complex<double>* const>,
                                                    std::complex<double>*) const;

}  // namespace dydp::symbolic
