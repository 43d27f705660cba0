#include "io/csv.hpp"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "engine/framework/errors.hpp"
#include "engine/framework/numbers.hpp"

namespace dydp::io {

using engine::InputError;
using engine::parse_number;
namespace {

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) {
    const auto b = cell.find_first_not_of(" \t\r"), e = cell.find_last_not_of(" \t\r");
    cells.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
  }
  return cells;
}

}  // namespace

int CsvFile::find(const std::string& name) const {
  for (size_t c = 0; c < names.size(); ++c)
    if (names[c] == name) return static_cast<int>(c);
  return -1;
}

CsvFile read_csv(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) throw InputError(path, 0, "", "is a folder, not a CSV file");
  std::ifstream in(path);
  if (!in) throw InputError(path, 0, "", "cannot open the CSV file");
  CsvFile csv;
  csv.path = path;
  std::string line;
  if (!std::getline(in, line)) throw InputError(path, 1, "", "empty CSV file");
  csv.names = split(line);
  csv.columns.resize(csv.names.size());
  for (int row = 2; std::getline(in, line); ++row) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const auto cells = split(line);
    if (cells.size() != csv.names.size())
      throw InputError(path, row, "", "expected " + std::to_string(csv.names.size()) + " values, found " +
                                          std::to_string(cells.size()));
    for (size_t c = 0; c < cells.size(); ++c) {
      double v = 0;
      if (!parse_number(cells[c], v)) throw InputError(path, row, csv.names[c], "malformed number '" + cells[c] + "'");
      csv.columns[c].push_back(v);
    }
  }
  return csv;
}

}  // namespace dydp::io
