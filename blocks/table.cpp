// source.table: a column of a CSV file against its time column, linearly interpolated and held
// constant outside the table. Its values are data, not parameters: its tangent is zero.
#include <algorithm>
#include <fstream>
#include <sstream>

#include "engine/errors.hpp"
#include "engine/registry.hpp"

namespace dydp::blocks {
namespace {

using engine::Block;
using engine::DirView;
using engine::Eval;
using engine::InputError;
using engine::Seeds;

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) {
    const auto b = cell.find_first_not_of(" \t\r"), e = cell.find_last_not_of(" \t\r");
    cells.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
  }
  return cells;
}

class Table : public Block {
 public:
  explicit Table(const engine::BlockSettings& s) {
    const std::string file = s.path("file");
    const std::string time_column = s.text("time_column");
    const std::string column = s.text("column");
    std::ifstream in(file);
    if (!in) s.fail("file", "cannot open '" + file + "'");
    std::string line;
    if (!std::getline(in, line)) throw InputError(file, 1, "", "empty CSV file");
    const auto header = split_csv_line(line);
    const auto find = [&](const std::string& name, const char* key) {
      auto it = std::find(header.begin(), header.end(), name);
      if (it == header.end()) s.fail(key, "no column '" + name + "' in " + file);
      return static_cast<size_t>(it - header.begin());
    };
    const size_t ct = find(time_column, "time_column"), cy = find(column, "column");
    for (int row = 2; std::getline(in, line); ++row) {
      if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
      const auto cells = split_csv_line(line);
      double t = 0, y = 0;
      if (cells.size() <= std::max(ct, cy) || !engine::parse_number(cells[ct], t) ||
          !engine::parse_number(cells[cy], y))
        throw InputError(file, row, column, "malformed row");
      if (!t_.empty() && !(t > t_.back()))
        throw InputError(file, row, time_column, "times must increase");
      t_.push_back(t);
      y_.push_back(y);
    }
    if (t_.empty()) throw InputError(file, 2, column, "the table has no rows");
    declare_output("y", 1);
  }

  void outputs(const Eval& e, double* const* y) const override {
    if (e.t <= t_.front()) { y[0][0] = y_.front(); return; }
    if (e.t >= t_.back()) { y[0][0] = y_.back(); return; }
    const size_t k = std::upper_bound(t_.begin(), t_.end(), e.t) - t_.begin();
    const double w = (e.t - t_[k - 1]) / (t_[k] - t_[k - 1]);
    y[0][0] = (1 - w) * y_[k - 1] + w * y_[k];
  }
  void outputs_tangent(const Eval&, const Seeds& s, const DirView* dy) const override {
    for (int d = 0; d < s.directions; ++d) dy[0](0, d) = 0.0;
  }

 private:
  std::vector<double> t_, y_;
};

const engine::BlockRegistration table({
    "source.table", "sources", "A CSV column against time, linearly interpolated.",
    {},
    {{"file", "CSV file, relative to the scene", "", true},
     {"column", "column to output", "", true},
     {"time_column", "column holding time [s]", "t", false}},
    [](const engine::BlockSettings& s) -> std::unique_ptr<Block> { return std::make_unique<Table>(s); }});

}  // namespace
}  // namespace dydp::blocks
