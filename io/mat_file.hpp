// A MAT v5 file (MATLAB, Octave, scipy.io.loadmat) written through libmatio: named double
// matrices, cell arrays of strings, and JSON documents as structs. Written to a temporary name
// and renamed by commit(), so that a failure leaves no half-written file.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

struct _mat_t;
struct matvar_t;

namespace dydp::io {

class MatFile {
 public:
  explicit MatFile(std::string path);
  ~MatFile();
  MatFile(const MatFile&) = delete;
  MatFile& operator=(const MatFile&) = delete;

  /// A rows x cols double matrix from column-major data.
  void matrix(const std::string& name, size_t rows, size_t cols, const std::vector<double>& column_major);
  /// A 1 x n cell array of strings.
  void strings(const std::string& name, const std::vector<std::string>& items);
  /// A JSON value: objects become structs (keys made valid field names: other characters
  /// become '_'), arrays of numbers row vectors, arrays of strings or of mixed values cells,
  /// numbers and booleans 1 x 1 doubles, strings char rows, null an empty matrix.
  void json(const std::string& name, const nlohmann::ordered_json& value);
  /// Closes the file and gives it its name.
  void commit();

  /// A JSON key as a MATLAB field name (letters, digits and '_', a letter first, 63 at most).
  static std::string field_name(const std::string& key);

 private:
  void write(matvar_t* var);
  std::string path_, tmp_;
  _mat_t* mat_ = nullptr;
};

}  // namespace dydp::io
