// Numeric CSV files with a header line (recorded test-bench input, tables): columns by name,
// every malformed cell reported as file:row: column.
#pragma once

#include <string>
#include <vector>

namespace dydp::io {

struct CsvFile {
  std::string path;
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;  ///< columns[c][row]

  /// Index of the named column, or -1.
  int find(const std::string& name) const;
};

/// Reads a comma-separated file whose first line names the columns and whose other lines hold
/// numbers (blank lines skipped). Throws InputError(path, row, column, ...) on a bad cell or
/// row length.
CsvFile read_csv(const std::string& path);

}  // namespace dydp::io
