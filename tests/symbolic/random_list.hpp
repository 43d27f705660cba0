// Randomly generated equation lists for the symbolic tests: hundreds of assignments using every
// node kind, with operands shaped so that values stay in the domain and of moderate size.
#pragma once

#include <random>
#include <string>
#include <vector>

#include "symbolic/equation_list.hpp"

namespace dydp::symbolic::testing {

struct RandomModel {
  ArrayId q, qd, p;
  std::vector<Expr> aux;  // every assigned (or inlined) value, in order
};

// Fills `list` with `count` assignments over inputs q[4], qd[4] and parameters p[3] of the
// list's context, and flags `outputs` of them (the last one always) as outputs.
inline RandomModel make_random_list(EquationList& list, std::size_t count, std::size_t outputs,
                                    unsigned seed) {
  Context& ctx = list.context();
  RandomModel m;
  m.q = ctx.add_array("q", 4, SymbolKind::Input);
  m.qd = ctx.add_array("qd", 4, SymbolKind::Input);
  m.p = ctx.add_array("p", 3, SymbolKind::Parameter);
  std::vector<Expr> pool;
  for (ArrayId a : {m.q, m.qd, m.p}) {
    for (std::size_t i = 0; i < ctx.array(a).elements.size(); ++i) pool.push_back(ctx.element(a, i));
  }
  std::mt19937 rng(seed);
  auto pick = [&]() {
    // mostly recent values, so chains are deep
    std::uniform_int_distribution<std::size_t> recent(pool.size() > 12 ? pool.size() - 12 : 0, pool.size() - 1);
    std::uniform_int_distribution<std::size_t> any(0, pool.size() - 1);
    return std::uniform_int_distribution<int>(0, 2)(rng) ? pool[recent(rng)] : pool[any(rng)];
  };
  auto positive = [&](Expr x) { return x * x + 0.5; };
  for (std::size_t k = 0; k < count; ++k) {
    const Expr a = pick(), b = pick(), c = pick();
    Expr r;
    bool bound = false;
    switch (std::uniform_int_distribution<int>(0, 21)(rng)) {
      case 0: r = a + b; bound = true; break;
      case 1: r = a - b * 0.75; bound = true; break;
      case 2: r = a * b; bound = true; break;
      case 3: r = -a * c + b; bound = true; break;
      case 4: r = a / positive(b); break;
      case 5: r = pow(a, 3.0) - b; bound = true; break;
      case 6: r = pow(positive(a), 0.7); bound = true; break;
      case 7: r = pow(positive(a), b * 0.3); bound = true; break;
      case 8: r = sin(a) * b + cos(c); break;
      case 9: r = cos(a) - sin(b); break;
      case 10: r = tan(0.5 * sin(a)); break;
      case 11: r = atan2(a, b + 2.0); break;
      case 12: r = sqrt(positive(a)); break;
      case 13: r = exp(sin(a)); break;
      case 14: r = log(positive(a)); break;
      case 15: r = abs(a) * b; break;
      case 16: r = sign(a) * b + c; break;
      case 17: r = min(a, b); break;
      case 18: r = max(a, b) * c; break;
      case 19: r = select(a, b, c * 2.0); break;
      case 20: r = a * b / positive(c) + pow(b, 2.0); bound = true; break;
      default: r = 1.0 / (a * a + 1.0) + pow(positive(b), -2.0); break;
    }
    if (bound) r = std::uniform_int_distribution<int>(0, 1)(rng) ? sin(r) : r / positive(r);
    const Expr v = list.assign("x" + std::to_string(k), r);
    pool.push_back(v);
    m.aux.push_back(v);
  }
  std::uniform_int_distribution<std::size_t> any(0, m.aux.size() - 1);
  for (std::size_t j = 0; j + 1 < outputs; ++j) {
    list.add_output("y" + std::to_string(j), m.aux[any(rng)]);
  }
  list.add_output("y_last", m.aux.back());
  return m;
}

// Deterministic pseudo-random input values (away from the non-smooth points of abs/sign/min).
inline std::vector<double> random_values(std::size_t n, unsigned seed, double scale = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-scale, scale);
  std::vector<double> v(n);
  for (double& x : v) x = u(rng);
  return v;
}

}  // namespace dydp::symbolic::testing
