// Reader of the equation-list text format (`*.eqs`, described in docs/symbolic.md): arrays of
// inputs and parameters, assignments `NAME = expr` in evaluation order, flagged outputs, and the
// arrays a tangent function is seeded on. Errors carry `file:line: message`.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "symbolic/equation_list.hpp"

namespace dydp::symbolic {

class ParseError : public std::runtime_error {
 public:
  ParseError(const std::string& file, int line, const std::string& message)
      : std::runtime_error(file + ":" + std::to_string(line) + ": " + message), file_(file), line_(line) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  std::string file_;
  int line_;
};

struct EqsModel {
  std::string name;                      // `model NAME`, else the file's stem
  std::unique_ptr<Context> context;
  std::unique_ptr<EquationList> list;    // as written: not eliminated
  std::vector<ArrayId> tangent_arrays;   // `tangent q qd`; empty when no tangent is wanted
};

// Parses `text`; `file` only names the source in error messages.
EqsModel parse_eqs(std::string_view text, const std::string& file);
// Reads and parses a file; a file that cannot be read is a ParseError at line 0.
EqsModel read_eqs(const std::string& path);

}  // namespace dydp::symbolic
