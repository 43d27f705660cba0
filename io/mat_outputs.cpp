#include "io/mat_outputs.hpp"

#include <cstdlib>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "io/mat_file.hpp"
#include "io/output_writer.hpp"

namespace dydp::io {
namespace {

void add_documents(MatFile& mat, const JsonDocuments& documents) {
  for (const auto& [name, text] : documents) mat.json(name, nlohmann::ordered_json::parse(text));
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) cells.push_back(cell);
  return cells;
}

}  // namespace

void write_run_mat(const std::string& path, const engine::Diagram& d, const engine::RunResult& r,
                   const JsonDocuments& extra) {
  const size_t n = r.t.size(), nsig = r.signal_names.size();
  const size_t ns = r.signal_sensitivities ? r.sensitivity_names.size() : 0;  // adjoint: the objectives' only
  std::vector<std::string> names = {"t"}, units = {"s"}, signal_units;
  for (size_t i = 0; i < nsig; ++i) {
    names.push_back(r.signal_names[i]);
    signal_units.push_back(d.signal_unit(d.logged[i].offset));
    units.push_back(signal_units.back());
  }
  for (size_t dir = 0; dir < ns; ++dir) {
    const std::string& p = r.sensitivity_names[dir];
    const std::string& punit = d.parameters[d.find_parameter(p)].unit;
    for (size_t i = 0; i < nsig; ++i) {
      names.push_back("d(" + r.signal_names[i] + ")/d(" + p + ")");
      units.push_back(engine::unit_per(signal_units[i], punit));
    }
  }
  // Column-major: column c of signals.csv is table[c * n + k].
  const size_t cols = names.size();
  std::vector<double> table(n * cols);
  for (size_t k = 0; k < n; ++k) {
    table[k] = r.t[k];
    for (size_t i = 0; i < nsig; ++i) table[(1 + i) * n + k] = r.value(static_cast<int>(k), static_cast<int>(i));
    for (size_t dir = 0; dir < ns; ++dir)
      for (size_t i = 0; i < nsig; ++i)
        table[(1 + nsig + dir * nsig + i) * n + k] = r.tangent(static_cast<int>(k), static_cast<int>(dir), static_cast<int>(i));
  }
  MatFile mat(path);
  mat.strings("names", names);
  mat.strings("units", units);
  mat.matrix("signals", n, cols, table);
  mat.json("objectives", nlohmann::ordered_json::parse(io::objectives_json(r))["objectives"]);
  mat.json("run", nlohmann::ordered_json::parse(io::run_json(d, r)));
  add_documents(mat, extra);
  mat.commit();
}

void write_table_mat(const std::string& path, const std::string& csv_text, const JsonDocuments& documents) {
  std::istringstream in(csv_text);
  std::string line;
  if (!std::getline(in, line)) throw std::logic_error("write_table_mat: no header line");
  const std::vector<std::string> names = split(line);
  std::vector<std::vector<double>> rows;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<double> row;
    for (const std::string& cell : split(line)) {
      char* end = nullptr;
      row.push_back(std::strtod(cell.c_str(), &end));
      if (cell.empty() || *end != '\0') throw std::logic_error("write_table_mat: '" + cell + "' is not a number");
    }
    if (row.size() != names.size()) throw std::logic_error("write_table_mat: row length differs from the header");
    rows.push_back(std::move(row));
  }
  std::vector<double> table(rows.size() * names.size());
  for (size_t k = 0; k < rows.size(); ++k)
    for (size_t c = 0; c < names.size(); ++c) table[c * rows.size() + k] = rows[k][c];
  MatFile mat(path);
  mat.strings("names", names);
  mat.matrix("table", rows.size(), names.size(), table);
  add_documents(mat, documents);
  mat.commit();
}

}  // namespace dydp::io
