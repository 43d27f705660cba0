// The two kinds of failure dydp reports: bad user input (file, line, field; exit 2) and
// solver failures (time, block, reason; exit 1).
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace dydp::engine {

/// A number in a message as a rule states it: 1e-12, 0.5, 1e+06, inf (six significant digits).
inline std::string format_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

/// Bad input: a scene, a CSV table, a command-line value. what() reads "file:line: field: message".
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, int line, std::string field, const std::string& message)
      : std::runtime_error(format(file, line, field, message)),
        file_(std::move(file)), line_(line), field_(std::move(field)) {}
  const std::string& file() const { return file_; }
  int line() const { return line_; }
  const std::string& field() const { return field_; }

 private:
  static std::string format(const std::string& file, int line, const std::string& field,
                            const std::string& message) {
    std::ostringstream s;
    s << file;
    if (line > 0) s << ':' << line;
    s << ": ";
    if (!field.empty()) s << field << ": ";
    s << message;
    return s.str();
  }
  std::string file_;
  int line_;
  std::string field_;
};

/// The integration could not go on. what() reads "t = T s: block B: reason".
class SolverError : public std::runtime_error {
 public:
  SolverError(double time, std::string block, const std::string& reason)
      : std::runtime_error(format(time, block, reason)), time_(time), block_(std::move(block)) {}
  double time() const { return time_; }
  const std::string& block() const { return block_; }

 private:
  static std::string format(double time, const std::string& block, const std::string& reason) {
    std::ostringstream s;
    s << "t = " << time << " s: ";
    if (!block.empty()) s << "block " << block << ": ";
    s << reason;
    return s.str();
  }
  double time_;
  std::string block_;
};

/// A fixed-step method cannot retry: an input out of a block's domain ends the run. The
/// reason comes as "block: why" from the evaluator. Failure: what is made of (t, block, why),
/// the run's SolverError or a retried step's own failure (Rosenbrock-W's StageFailure).
template <class Failure = SolverError, class DomainError>
Failure domain_failure(double t, const DomainError& e) {
  const auto colon = e.reason.find(": ");
  if (colon == std::string::npos) return Failure{t, "", "input out of a block's domain: " + e.reason};
  return Failure{t, e.reason.substr(0, colon), "input out of the block's domain: " + e.reason.substr(colon + 2)};
}

}  // namespace dydp::engine
