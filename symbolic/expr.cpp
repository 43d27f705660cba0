// Node storage, hash-consing and symbols of a Context; the simplifying constructors are in
// simplify.cpp.
#include "symbolic/expr.hpp"

#include <bit>
#include <cctype>
#include <stdexcept>

namespace dydp::symbolic {
namespace {

constexpr NodeId kEmpty = 0xFFFFFFFFu;

// Words a generated C++ function must not use as local names.
const std::unordered_set<std::string>& reserved_words() {
  static const std::unordered_set<std::string> words = {
      "alignas", "alignof", "and", "asm", "auto", "bool", "break", "case", "catch", "char",
      "class", "const", "constexpr", "continue", "default", "delete", "do", "double", "else",
      "enum", "explicit", "extern", "false", "float", "for", "friend", "goto", "if", "inline",
      "int", "long", "namespace", "new", "noexcept", "not", "nullptr", "operator", "or",
      "private", "protected", "public", "register", "return", "short", "signed", "sizeof",
      "static", "struct", "switch", "template", "this", "throw", "true", "try", "typedef",
      "typename", "union", "unsigned", "using", "virtual", "void", "volatile", "while", "xor",
      "std", "out", "dout", "nd", "d", "sin", "cos", "tan", "sqrt", "exp", "log", "pow"};
  return words;
}

std::string sanitize(std::string_view wanted) {
  std::string name;
  for (char c : wanted) {
    name += (std::isalnum(static_cast<unsigned char>(c)) || c == '_') ? c : '_';
  }
  if (name.empty() || std::isdigit(static_cast<unsigned char>(name[0]))) name = "v" + name;
  return name;
}

}  // namespace

const char* op_name(Op op) {
  switch (op) {
    case Op::Constant: return "constant";
    case Op::Symbol: return "symbol";
    case Op::Add: return "add";
    case Op::Mul: return "mul";
    case Op::Neg: return "neg";
    case Op::Div: return "div";
    case Op::Pow: return "pow";
    case Op::Sin: return "sin";
    case Op::Cos: return "cos";
    case Op::Tan: return "tan";
    case Op::Atan2: return "atan2";
    case Op::Sqrt: return "sqrt";
    case Op::Exp: return "exp";
    case Op::Log: return "log";
    case Op::Abs: return "abs";
    case Op::Sign: return "sign";
    case Op::Min: return "min";
    case Op::Max: return "max";
    case Op::Select: return "select";
  }
  return "?";
}

Context::Context() {
  table_.assign(1024, kEmpty);
  for (const auto& w : reserved_words()) names_.insert(w);
}

std::uint64_t Context::hash_of(Op op, std::span<const NodeId> children,
                               std::uint64_t payload) const {
  // splitmix64 finaliser on each word: constants differ mostly in their high bits, and the
  // table is indexed by the low bits.
  auto mix = [](std::uint64_t x) {
    x ^= x >> 30;
    x *= 0xBF58476D1CE4E5B9ull;
    x ^= x >> 27;
    x *= 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  };
  std::uint64_t h = mix(payload ^ (static_cast<std::uint64_t>(op) << 56));
  for (NodeId c : children) h = mix(h ^ (c + 0x9E3779B97F4A7C15ull));
  return h;
}

void Context::grow_table() {
  std::vector<NodeId> table(table_.size() * 2, kEmpty);
  const std::size_t mask = table.size() - 1;
  for (NodeId id = 0; id < nodes_.size(); ++id) {
    const Node& n = nodes_[id];
    if (n.op == Op::Symbol) continue;  // symbols are unique by construction, never looked up
    std::size_t slot = hash_of(n.op, children(id), n.payload) & mask;
    while (table[slot] != kEmpty) slot = (slot + 1) & mask;
    table[slot] = id;
  }
  table_ = std::move(table);
}

NodeId Context::intern(Op op, std::span<const NodeId> kids, std::uint64_t payload) {
  if (op != Op::Symbol) {
    const std::size_t mask = table_.size() - 1;
    std::size_t slot = hash_of(op, kids, payload) & mask;
    for (; table_[slot] != kEmpty; slot = (slot + 1) & mask) {
      const NodeId id = table_[slot];
      const Node& n = nodes_[id];
      if (n.op != op || n.payload != payload || n.child_count != kids.size()) continue;
      auto existing = children(id);
      if (std::equal(existing.begin(), existing.end(), kids.begin())) return id;
    }
  }
  // `kids` may point into children_ itself (a sub-range of an existing node): copy it before
  // children_ grows.
  std::vector<NodeId> own_copy;
  if (!kids.empty() && kids.data() >= children_.data() && kids.data() < children_.data() + children_.size()) {
    own_copy.assign(kids.begin(), kids.end());
    kids = own_copy;
  }
  const auto id = static_cast<NodeId>(nodes_.size());
  if (id == kEmpty) throw std::length_error("symbolic::Context: too many nodes");
  nodes_.push_back(Node{op, static_cast<std::uint32_t>(kids.size()),
                        static_cast<std::uint32_t>(children_.size()), payload});
  children_.insert(children_.end(), kids.begin(), kids.end());
  if (op != Op::Symbol) {
    if (2 * nodes_.size() > table_.size()) {
      grow_table();
    } else {
      const std::size_t mask = table_.size() - 1;
      std::size_t slot = hash_of(op, kids, payload) & mask;
      while (table_[slot] != kEmpty) slot = (slot + 1) & mask;
      table_[slot] = id;
    }
  }
  return id;
}

NodeId Context::make_constant(double v) {
  if (v == 0.0) v = 0.0;  // one zero: -0.0 and 0.0 are the same node
  return intern(Op::Constant, {}, std::bit_cast<std::uint64_t>(v));
}

double Context::value(NodeId n) const {
  if (nodes_[n].op != Op::Constant) throw std::logic_error("symbolic: value() of a non-constant");
  return std::bit_cast<double>(nodes_[n].payload);
}

bool Context::is_symbol(NodeId n, SymbolKind kind) const {
  return op(n) == Op::Symbol && symbols_[nodes_[n].payload].kind == kind;
}

const Symbol& Context::symbol(NodeId n) const {
  if (op(n) != Op::Symbol) throw std::logic_error("symbolic: symbol() of a non-symbol node");
  return symbols_[nodes_[n].payload];
}

const Symbol* Context::find_symbol(std::string_view name) const {
  auto it = symbol_by_name_.find(std::string(name));
  return it == symbol_by_name_.end() ? nullptr : &symbols_[it->second];
}

std::string Context::unique_name(std::string_view wanted) {
  std::string base = sanitize(wanted);
  if (names_.insert(base).second) return base;
  // next free numbered variant, remembered per base so repeated names stay O(1)
  std::size_t& k = next_suffix_[base];
  std::string name;
  do {
    name = base + "_" + std::to_string(++k);
  } while (!names_.insert(name).second);
  return name;
}

NodeId Context::new_symbol(std::string name, SymbolKind kind, ArrayId array,
                           std::uint32_t index) {
  const std::size_t s = symbols_.size();
  const NodeId node = intern(Op::Symbol, {}, s);
  symbol_by_name_[name] = s;
  symbols_.push_back(Symbol{std::move(name), kind, array, index, node});
  return node;
}

ArrayId Context::add_array(std::string name, std::size_t size, SymbolKind kind,
                           std::vector<std::string> element_names) {
  if (kind == SymbolKind::Aux) throw std::invalid_argument("symbolic: arrays hold inputs, not auxiliaries");
  if (!element_names.empty() && element_names.size() != size) {
    throw std::invalid_argument("symbolic: array '" + name + "': element names do not match its size");
  }
  if (sanitize(name) != name || names_.count(name) != 0) {
    throw std::invalid_argument("symbolic: array name '" + name + "' is not a free C++ identifier");
  }
  names_.insert(name);
  const auto id = static_cast<ArrayId>(arrays_.size());
  arrays_.push_back(Array{name, kind, {}, id});
  for (std::size_t i = 0; i < size; ++i) {
    std::string wanted = element_names.empty() ? name + std::to_string(i + 1) : element_names[i];
    arrays_[id].elements.push_back(
        new_symbol(unique_name(wanted), kind, id, static_cast<std::uint32_t>(i)));
  }
  return id;
}

ArrayId Context::seed_array(ArrayId of) {
  for (ArrayId a = 0; a < arrays_.size(); ++a) {
    if (arrays_[a].kind == SymbolKind::Seed && arrays_[a].seed_of == of && a != of) return a;
  }
  names_.insert("seed_" + arrays_.at(of).name);  // the tangent function's argument
  return new_seed_array(of, unique_name("d" + arrays_.at(of).name), "");
}

ArrayId Context::new_seed_array(ArrayId of, std::string name, std::string_view separator) {
  const auto id = static_cast<ArrayId>(arrays_.size());
  arrays_.push_back(Array{name, SymbolKind::Seed, {}, of});
  for (std::size_t i = 0; i < arrays_[of].elements.size(); ++i) {
    arrays_[id].elements.push_back(new_symbol(unique_name(name + std::string(separator) + std::to_string(i + 1)),
                                              SymbolKind::Seed, id, static_cast<std::uint32_t>(i)));
  }
  return id;
}

ArrayId Context::add_seed_array(ArrayId of, std::string_view suffix) {
  seed_array(of);  // the generic one first, so that seed_array never returns this one
  return new_seed_array(of, unique_name("d" + arrays_.at(of).name + "_" + std::string(suffix)), "_");
}

ArrayId Context::weight_array(std::size_t size) {
  for (ArrayId a = 0; a < arrays_.size(); ++a) {
    const Array& arr = arrays_[a];
    if (arr.kind == SymbolKind::Seed && arr.seed_of == a && arr.elements.size() == size) return a;
  }
  const auto id = static_cast<ArrayId>(arrays_.size());
  arrays_.push_back(Array{unique_name("wbar"), SymbolKind::Seed, {}, id});
  for (std::size_t i = 0; i < size; ++i) {
    arrays_[id].elements.push_back(new_symbol(unique_name(arrays_[id].name + std::to_string(i + 1)),
                                              SymbolKind::Seed, id, static_cast<std::uint32_t>(i)));
  }
  return id;
}

std::optional<ArrayId> Context::find_array(std::string_view name) const {
  for (ArrayId a = 0; a < arrays_.size(); ++a) {
    if (arrays_[a].name == name) return a;
  }
  return std::nullopt;
}

Expr Context::element(ArrayId array, std::size_t index) {
  return Expr(this, arrays_.at(array).elements.at(index));
}

Expr Context::aux(std::string_view name) {
  return Expr(this, new_symbol(unique_name(name), SymbolKind::Aux, 0, 0));
}

bool Context::is_abbreviation(NodeId n) const {
  return n < abbreviation_flags_.size() && abbreviation_flags_[n];
}

const std::string& Context::abbreviation_name(NodeId n) const {
  return abbreviations_.at(n);
}

// --- handles and operators --------------------------------------------------------------------

Op Expr::op() const { return context_->op(id_); }
bool Expr::is_constant() const { return op() == Op::Constant; }
bool Expr::is_constant(double v) const { return context_->is_constant(id_, v); }
double Expr::constant_value() const { return context_->value(id_); }

Expr operator+(Expr a, Expr b) { return a.context().add(a, b); }
Expr operator-(Expr a, Expr b) { return a.context().sub(a, b); }
Expr operator*(Expr a, Expr b) { return a.context().mul(a, b); }
Expr operator/(Expr a, Expr b) { return a.context().div(a, b); }
Expr operator-(Expr a) { return a.context().neg(a); }
Expr operator+(Expr a, double b) { return a + a.context().constant(b); }
Expr operator+(double a, Expr b) { return b.context().constant(a) + b; }
Expr operator-(Expr a, double b) { return a - a.context().constant(b); }
Expr operator-(double a, Expr b) { return b.context().constant(a) - b; }
Expr operator*(Expr a, double b) { return a * a.context().constant(b); }
Expr operator*(double a, Expr b) { return b.context().constant(a) * b; }
Expr operator/(Expr a, double b) { return a / a.context().constant(b); }
Expr operator/(double a, Expr b) { return b.context().constant(a) / b; }
Expr pow(Expr base, Expr exponent) { return base.context().pow(base, exponent); }
Expr pow(Expr base, double exponent) { return pow(base, base.context().constant(exponent)); }
Expr sin(Expr a) { return a.context().unary(Op::Sin, a); }
Expr cos(Expr a) { return a.context().unary(Op::Cos, a); }
Expr tan(Expr a) { return a.context().unary(Op::Tan, a); }
Expr atan2(Expr y, Expr x) { return y.context().binary(Op::Atan2, y, x); }
Expr sqrt(Expr a) { return a.context().unary(Op::Sqrt, a); }
Expr exp(Expr a) { return a.context().unary(Op::Exp, a); }
Expr log(Expr a) { return a.context().unary(Op::Log, a); }
Expr abs(Expr a) { return a.context().unary(Op::Abs, a); }
Expr sign(Expr a) { return a.context().unary(Op::Sign, a); }
Expr min(Expr a, Expr b) { return a.context().binary(Op::Min, a, b); }
Expr max(Expr a, Expr b) { return a.context().binary(Op::Max, a, b); }
Expr select(Expr c, Expr a, Expr b) { return c.context().select(c, a, b); }

}  // namespace dydp::symbolic
