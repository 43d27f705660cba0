// Symbolic expressions: hash-consed immutable nodes owned by a Context, simplified as they are
// built (constant folding, 0/1 rules, like-term and like-factor collection, canonical ordering),
// so that structurally equal expressions are one node. Expr is a cheap handle (context, node id).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace dydp::symbolic {

using NodeId = std::uint32_t;
using ArrayId = std::uint32_t;

// Node kinds. Add and Mul are n-ary; a Mul's constant coefficient, if any, is its first child
// (never +-1: a coefficient of -1 is a Neg). Select(c, a, b) is `c > 0 ? a : b`.
enum class Op : std::uint8_t {
  Constant, Symbol,
  Add, Mul, Neg, Div, Pow,
  Sin, Cos, Tan, Atan2, Sqrt, Exp, Log, Abs, Sign, Min, Max, Select,
};

const char* op_name(Op op);

// Inputs and parameters are elements of named arrays (the arguments of emitted functions);
// seeds are the direction arrays of tangent functions; auxiliaries are equation-list variables.
enum class SymbolKind : std::uint8_t { Input, Parameter, Seed, Aux };

struct Symbol {
  std::string name;        // display name: `q3` for element 2 of array q, `OM23` for an auxiliary
  SymbolKind kind;
  ArrayId array;           // for Input, Parameter, Seed
  std::uint32_t index;     // element index within the array (0-based)
  NodeId node;
};

struct Array {
  std::string name;        // C++ argument name of emitted functions (`q`, `qd`, `p`, `dq`)
  SymbolKind kind;
  std::vector<NodeId> elements;
  ArrayId seed_of;         // for Seed arrays: the array whose directions they carry
};

class Context;

// A handle on one node of a Context. Arithmetic operators and the free functions below build
// simplified nodes in the same context.
class Expr {
 public:
  Expr() = default;
  Expr(Context* context, NodeId id) : context_(context), id_(id) {}
  NodeId id() const { return id_; }
  Context& context() const { return *context_; }
  bool valid() const { return context_ != nullptr; }
  Op op() const;
  bool is_constant() const;
  bool is_constant(double value) const;
  bool is_zero() const { return is_constant(0.0); }
  double constant_value() const;
  friend bool operator==(Expr a, Expr b) { return a.id_ == b.id_ && a.context_ == b.context_; }

 private:
  Context* context_ = nullptr;
  NodeId id_ = 0;
};

// Owns the nodes, the symbols and the arrays of one model. Not thread safe; no global state.
class Context {
 public:
  Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  // --- symbols ---------------------------------------------------------------------------
  // A new array of `size` Input/Parameter symbols; element names default to `name<i+1>`.
  ArrayId add_array(std::string name, std::size_t size, SymbolKind kind,
                    std::vector<std::string> element_names = {});
  // The Seed array carrying directions for `array` (created on first call, named `d<name>`).
  ArrayId seed_array(ArrayId array);
  // A further Seed array for `array` (named `d<name>_<suffix>`), for a tangent whose blocks
  // each read seeds of their own (symbolic/grouped_tangent.hpp); seed_array keeps the first.
  ArrayId add_seed_array(ArrayId array, std::string_view suffix);
  // The Seed array of `size` output weights an adjoint function reads (symbolic/reverse.hpp),
  // created on first call for that size, named `wbar` (`wbar_2`, ... for further sizes). It
  // carries no array's directions: its seed_of is its own id, as for inputs.
  ArrayId weight_array(std::size_t size);
  Expr element(ArrayId array, std::size_t index);
  const Array& array(ArrayId id) const { return arrays_.at(id); }
  std::size_t array_count() const { return arrays_.size(); }
  std::optional<ArrayId> find_array(std::string_view name) const;
  // A new auxiliary variable; the name is made a unique C++ identifier.
  Expr aux(std::string_view name);
  const Symbol& symbol(NodeId symbol_node) const;
  const Symbol* find_symbol(std::string_view name) const;
  // Name of a trigonometric abbreviation (`S3`, `C3`) for sin/cos of an input or parameter.
  bool is_abbreviation(NodeId node) const;
  const std::string& abbreviation_name(NodeId node) const;

  // --- simplifying constructors -----------------------------------------------------------
  Expr constant(double value);
  Expr zero() { return constant(0.0); }
  Expr one() { return constant(1.0); }
  Expr add(Expr a, Expr b);
  Expr sub(Expr a, Expr b);
  Expr mul(Expr a, Expr b);
  Expr div(Expr a, Expr b);
  Expr neg(Expr a);
  Expr pow(Expr base, Expr exponent);
  Expr sum(std::span<const Expr> terms);
  Expr product(std::span<const Expr> factors);
  Expr unary(Op op, Expr a);             // Sin .. Sign, Neg
  Expr binary(Op op, Expr a, Expr b);    // Div, Pow, Atan2, Min, Max, Add, Mul
  Expr select(Expr condition, Expr if_positive, Expr otherwise);
  // Rebuilds a node of kind `op` from new children with all simplifications (used by passes).
  NodeId make(Op op, std::span<const NodeId> children);

  // --- node inspection --------------------------------------------------------------------
  std::size_t size() const { return nodes_.size(); }
  Op op(NodeId n) const { return nodes_[n].op; }
  // Valid until the next node is built: copy it before building nodes from its elements.
  std::span<const NodeId> children(NodeId n) const {
    return {children_.data() + nodes_[n].first_child, nodes_[n].child_count};
  }
  double value(NodeId n) const;           // Constant nodes only
  bool is_constant(NodeId n, double v) const { return op(n) == Op::Constant && value(n) == v; }
  bool is_symbol(NodeId n, SymbolKind kind) const;
  Expr expr(NodeId n) { return Expr(this, n); }

 private:
  struct Node {
    Op op;
    std::uint32_t child_count;
    std::uint32_t first_child;
    std::uint64_t payload;  // constant bits or symbol index
  };
  // Returns the existing node equal to (op, children, payload) or appends it (hash-consing).
  NodeId intern(Op op, std::span<const NodeId> children, std::uint64_t payload);
  std::uint64_t hash_of(Op op, std::span<const NodeId> children, std::uint64_t payload) const;
  void grow_table();
  std::string unique_name(std::string_view wanted);
  NodeId new_symbol(std::string name, SymbolKind kind, ArrayId array, std::uint32_t index);
  // A Seed array `name` for `of`, its elements named name<separator><i + 1>.
  ArrayId new_seed_array(ArrayId of, std::string name, std::string_view separator);

  // simplify.cpp
  // Canonical order of sum terms and product factors: by leading leaf (symbols, then
  // abbreviations, then the rest), then by node id; depends on the node only.
  std::tuple<int, NodeId, NodeId> order_key(NodeId n) const;
  NodeId make_add(std::span<const NodeId> terms);
  NodeId make_mul(std::span<const NodeId> factors);
  NodeId make_neg(NodeId a);
  NodeId make_div(NodeId a, NodeId b);
  NodeId make_pow(NodeId base, NodeId exponent);
  NodeId make_function(Op op, NodeId a);
  NodeId make_atan2(NodeId y, NodeId x);
  NodeId make_min_max(Op op, NodeId a, NodeId b);
  NodeId make_select(NodeId c, NodeId a, NodeId b);
  NodeId make_constant(double v);

  std::vector<Node> nodes_;
  std::vector<NodeId> children_;
  std::vector<NodeId> table_;  // open addressing; kEmpty marks free slots
  std::vector<Symbol> symbols_;
  std::vector<Array> arrays_;
  std::unordered_set<std::string> names_;
  std::unordered_map<std::string, std::size_t> next_suffix_;
  std::unordered_map<NodeId, std::string> abbreviations_;
  std::vector<char> abbreviation_flags_;  // by node: is an abbreviation (the fast test)
  std::unordered_map<std::string, std::size_t> symbol_by_name_;
};

// --- operators and functions on handles ------------------------------------------------------
Expr operator+(Expr a, Expr b);
Expr operator-(Expr a, Expr b);
Expr operator*(Expr a, Expr b);
Expr operator/(Expr a, Expr b);
Expr operator-(Expr a);
Expr operator+(Expr a, double b);
Expr operator+(double a, Expr b);
Expr operator-(Expr a, double b);
Expr operator-(double a, Expr b);
Expr operator*(Expr a, double b);
Expr operator*(double a, Expr b);
Expr operator/(Expr a, double b);
Expr operator/(double a, Expr b);
Expr pow(Expr base, Expr exponent);
Expr pow(Expr base, double exponent);
Expr sin(Expr a);
Expr cos(Expr a);
Expr tan(Expr a);
Expr atan2(Expr y, Expr x);
Expr sqrt(Expr a);
Expr exp(Expr a);
Expr log(Expr a);
Expr abs(Expr a);
Expr sign(Expr a);
Expr min(Expr a, Expr b);
Expr max(Expr a, Expr b);
Expr select(Expr condition, Expr if_positive, Expr otherwise);

}  // namespace dydp::symbolic

template <>
struct std::hash<dydp::symbolic::Expr> {
  std::size_t operator()(dydp::symbolic::Expr e) const noexcept { return e.id(); }
};
