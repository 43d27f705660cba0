// A line-oriented reader with a small recursive-descent expression parser:
//   expr    := term (('+' | '-') term)*
//   term    := unary (('*' | '/') unary)*
//   unary   := '-' unary | power
//   power   := primary ('^' unary)?
//   primary := number | NAME | NAME '[' index ']' | FUNCTION '(' expr (',' expr)* ')' | '(' expr ')'
#include "symbolic/eqs_reader.hpp"

#include <cctype>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unordered_map>

namespace dydp::symbolic {
namespace {

bool is_name_start(char c) { return std::isalpha(static_cast<unsigned char>(c)) || c == '_'; }
bool is_name_char(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }

class Reader {
 public:
  Reader(const std::string& file, EqsModel& model) : file_(file), model_(model) {}

  void line(std::string_view text, int number) {
    line_ = number;
    text_ = text;
    pos_ = 0;
    skip_space();
    if (at_end()) return;
    const std::string word = name();
    if (word.empty()) fail("expected a statement (model, input, param, tangent, output or NAME = expr)");
    skip_space();
    if (peek() == '=') {
      ++pos_;
      assignment(word);
    } else if (word == "model") {
      model_.name = required_name("a model name");
      if (!model_.list->assignments().empty()) fail("'model' must come before the equations");
    } else if (word == "input" || word == "param") {
      array(word == "input" ? SymbolKind::Input : SymbolKind::Parameter);
    } else if (word == "output") {
      output();
    } else if (word == "tangent") {
      tangent();
    } else {
      fail("unknown statement '" + word + "' (expected model, input, param, tangent, output or NAME = expr)");
    }
    skip_space();
    if (!at_end()) fail(std::string("unexpected '") + peek() + "'");
  }

  void finish() {
    if (model_.list->outputs().empty()) throw ParseError(file_, line_, "no output: flag at least one with 'output NAME'");
  }

 private:
  static constexpr std::size_t kMaxElements = 100000;
  std::size_t elements_ = 0;  // of the arrays declared so far

  Context& ctx() { return *model_.context; }

  [[noreturn]] void fail(const std::string& message) const { throw ParseError(file_, line_, message); }

  bool at_end() const { return pos_ >= text_.size() || text_[pos_] == '#'; }
  char peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
  void skip_space() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
  }
  void expect(char c) {
    skip_space();
    if (peek() != c) fail(std::string("expected '") + c + "'");
    ++pos_;
  }
  std::string name() {
    skip_space();
    const std::size_t start = pos_;
    if (pos_ < text_.size() && is_name_start(text_[pos_])) {
      while (pos_ < text_.size() && is_name_char(text_[pos_])) ++pos_;
    }
    return std::string(text_.substr(start, pos_ - start));
  }
  std::string required_name(const char* what) {
    std::string n = name();
    if (n.empty()) fail(std::string("expected ") + what);
    return n;
  }
  std::size_t integer(const char* what) {
    skip_space();
    std::size_t value = 0;
    const auto [end, ec] = std::from_chars(text_.data() + pos_, text_.data() + text_.size(), value);
    if (ec != std::errc() || end == text_.data() + pos_) fail(std::string("expected ") + what);
    pos_ = static_cast<std::size_t>(end - text_.data());
    return value;
  }

  void array(SymbolKind kind) {
    const std::string array_name = required_name("an array name");
    if (values_.count(array_name) || ctx().find_array(array_name)) fail("'" + array_name + "' is already defined");
    const std::size_t size = integer("the array size");
    if (size == 0) fail("array '" + array_name + "' must have at least one element");
    // A bound on what the list's inputs and parameters may take (each element is a symbol):
    // without it `input q 12936409836691885623` asked for the memory of that many symbols.
    if (size > kMaxElements - elements_)
      fail("array '" + array_name + "' of " + std::to_string(size) + " elements: the inputs and parameters of a list have at most " +
           std::to_string(kMaxElements) + " elements in all");
    elements_ += size;
    if (!model_.list->assignments().empty()) fail("declare inputs and parameters before the equations");
    try {
      ctx().add_array(array_name, size, kind);
    } catch (const std::invalid_argument& e) {
      fail("'" + array_name + "' cannot name an array (reserved or not an identifier)");
    }
  }

  void assignment(const std::string& target) {
    if (values_.count(target) || ctx().find_array(target)) fail("'" + target + "' is already defined");
    if (functions().count(target)) fail("'" + target + "' is a function name");
    const Expr value = expression();
    values_.emplace(target, model_.list->assign(target, value));
  }

  void output() {
    const std::string output_name = required_name("an output name");
    skip_space();
    Expr value;
    if (peek() == '=') {
      ++pos_;
      value = expression();
    } else {
      auto it = values_.find(output_name);
      if (it == values_.end()) fail("output '" + output_name + "' is not defined");
      value = it->second;
    }
    for (const Output& o : model_.list->outputs()) {
      if (o.name == output_name) fail("output '" + output_name + "' is flagged twice");
    }
    model_.list->add_output(output_name, value);
  }

  void tangent() {
    for (;;) {
      const std::string a = name();
      if (a.empty()) break;
      const auto id = ctx().find_array(a);
      if (!id || ctx().array(*id).kind == SymbolKind::Seed) fail("'" + a + "' is not an input or parameter array");
      model_.tangent_arrays.push_back(*id);
      skip_space();
    }
    if (model_.tangent_arrays.empty()) fail("expected the arrays the tangent is seeded on");
  }

  static const std::unordered_map<std::string, int>& functions() {
    static const std::unordered_map<std::string, int> arity = {
        {"sin", 1}, {"cos", 1}, {"tan", 1}, {"sqrt", 1}, {"exp", 1}, {"log", 1}, {"abs", 1},
        {"sign", 1}, {"atan2", 2}, {"min", 2}, {"max", 2}, {"pow", 2}, {"select", 3}};
    return arity;
  }

  Expr expression() {
    Expr left = term();
    for (;;) {
      skip_space();
      if (peek() == '+') {
        ++pos_;
        left = left + term();
      } else if (peek() == '-') {
        ++pos_;
        left = left - term();
      } else {
        return left;
      }
    }
  }

  Expr term() {
    Expr left = unary();
    for (;;) {
      skip_space();
      if (peek() == '*') {
        ++pos_;
        left = left * unary();
      } else if (peek() == '/') {
        ++pos_;
        left = left / unary();
      } else {
        return left;
      }
    }
  }

  Expr unary() {
    skip_space();
    if (peek() == '-') {
      ++pos_;
      return -unary();
    }
    Expr base = primary();
    skip_space();
    if (peek() == '^') {
      ++pos_;
      return pow(base, unary());
    }
    return base;
  }

  Expr primary() {
    skip_space();
    const char c = peek();
    if (c == '(') {
      ++pos_;
      Expr e = expression();
      expect(')');
      return e;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') return number();
    const std::string word = name();
    if (word.empty()) fail(c == '\0' || c == '#' ? "expression ends too early" : std::string("unexpected '") + c + "'");
    skip_space();
    if (peek() == '(') return call(word);
    if (peek() == '[') {
      ++pos_;
      const auto array = ctx().find_array(word);
      if (!array) fail("'" + word + "' is not an input or parameter array");
      const std::size_t index = integer("an element index");
      expect(']');
      if (index >= ctx().array(*array).elements.size()) {
        fail("index " + std::to_string(index) + " is outside '" + word + "' (size " +
             std::to_string(ctx().array(*array).elements.size()) + ", indices start at 0)");
      }
      return ctx().element(*array, index);
    }
    auto it = values_.find(word);
    if (it == values_.end()) {
      if (ctx().find_array(word)) fail("'" + word + "' is an array: write " + word + "[index]");
      fail("'" + word + "' is not defined");
    }
    return it->second;
  }

  Expr number() {
    const char* begin = text_.data() + pos_;
    double value = 0.0;
    const auto [end, ec] = std::from_chars(begin, text_.data() + text_.size(), value);
    if (ec != std::errc() || end == begin) fail("malformed number");
    pos_ += static_cast<std::size_t>(end - begin);
    return ctx().constant(value);
  }

  Expr call(const std::string& function) {
    auto it = functions().find(function);
    if (it == functions().end()) fail("unknown function '" + function + "'");
    expect('(');
    std::vector<Expr> args{expression()};
    for (skip_space(); peek() == ','; skip_space()) {
      ++pos_;
      args.push_back(expression());
    }
    expect(')');
    if (static_cast<int>(args.size()) != it->second) {
      fail(function + " takes " + std::to_string(it->second) + " argument(s), not " + std::to_string(args.size()));
    }
    if (function == "sin") return sin(args[0]);
    if (function == "cos") return cos(args[0]);
    if (function == "tan") return tan(args[0]);
    if (function == "sqrt") return sqrt(args[0]);
    if (function == "exp") return exp(args[0]);
    if (function == "log") return log(args[0]);
    if (function == "abs") return abs(args[0]);
    if (function == "sign") return sign(args[0]);
    if (function == "atan2") return atan2(args[0], args[1]);
    if (function == "min") return min(args[0], args[1]);
    if (function == "max") return max(args[0], args[1]);
    if (function == "pow") return pow(args[0], args[1]);
    return select(args[0], args[1], args[2]);
  }

  std::string file_;
  EqsModel& model_;
  std::unordered_map<std::string, Expr> values_;
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 0;
};

}  // namespace

EqsModel parse_eqs(std::string_view text, const std::string& file) {
  EqsModel model;
  model.name = std::filesystem::path(file).stem().string();
  model.context = std::make_unique<Context>();
  model.list = std::make_unique<EquationList>(*model.context);
  Reader reader(file, model);
  int number = 0;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    reader.line(text.substr(start, end - start), ++number);
    start = end + 1;
  }
  reader.finish();
  return model;
}

EqsModel read_eqs(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ParseError(path, 0, "cannot read the file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_eqs(text.str(), path);
}

}  // namespace dydp::symbolic
