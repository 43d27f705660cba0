#include "io/mat_file.hpp"

#include <matio.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

namespace dydp::io {
namespace {

matvar_t* double_matrix(const char* name, size_t rows, size_t cols, const double* data) {
  size_t dims[2] = {rows, cols};
  // matio copies the data (no MAT_F_DONT_COPY_DATA).
  return Mat_VarCreate(name, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, const_cast<double*>(data), 0);
}

matvar_t* char_row(const char* name, const std::string& text) {
  size_t dims[2] = {1, text.size()};
  return Mat_VarCreate(name, MAT_C_CHAR, MAT_T_UTF8, 2, dims, const_cast<char*>(text.data()), 0);
}

matvar_t* string_cell(const char* name, const std::vector<std::string>& items) {
  size_t dims[2] = {1, items.size()};
  matvar_t* cell = Mat_VarCreate(name, MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0);
  for (size_t k = 0; k < items.size(); ++k) Mat_VarSetCell(cell, static_cast<int>(k), char_row(nullptr, items[k]));
  return cell;
}

matvar_t* from_json(const char* name, const nlohmann::ordered_json& v) {
  if (v.is_object()) {
    std::vector<std::string> fields;
    for (const auto& [key, item] : v.items()) fields.push_back(MatFile::field_name(key));
    std::vector<const char*> names;
    for (const auto& f : fields) names.push_back(f.c_str());
    size_t dims[2] = {1, 1};
    matvar_t* s = Mat_VarCreateStruct(name, 2, dims, names.data(), static_cast<unsigned>(names.size()));
    size_t k = 0;
    for (const auto& [key, item] : v.items()) {
      Mat_VarSetStructFieldByName(s, fields[k].c_str(), 0, from_json(nullptr, item));
      ++k;
    }
    return s;
  }
  if (v.is_array()) {
    bool numbers = true;
    for (const auto& item : v) numbers = numbers && item.is_number();
    if (numbers && !v.empty()) {
      std::vector<double> row;
      for (const auto& item : v) row.push_back(item.get<double>());
      return double_matrix(name, 1, row.size(), row.data());
    }
    size_t dims[2] = {1, v.size()};
    matvar_t* cell = Mat_VarCreate(name, MAT_C_CELL, MAT_T_CELL, 2, dims, nullptr, 0);
    for (size_t k = 0; k < v.size(); ++k) Mat_VarSetCell(cell, static_cast<int>(k), from_json(nullptr, v[k]));
    return cell;
  }
  if (v.is_string()) return char_row(name, v.get<std::string>());
  if (v.is_boolean()) {
    const double b = v.get<bool>() ? 1.0 : 0.0;
    return double_matrix(name, 1, 1, &b);
  }
  if (v.is_number()) {
    const double x = v.get<double>();
    return double_matrix(name, 1, 1, &x);
  }
  return double_matrix(name, 0, 0, nullptr);
}

}  // namespace

std::string MatFile::field_name(const std::string& key) {
  std::string f;
  for (unsigned char c : key) f += std::isalnum(c) || c == '_' ? static_cast<char>(c) : '_';
  if (f.empty() || !std::isalpha(static_cast<unsigned char>(f[0]))) f = "f_" + f;
  return f.substr(0, 63);
}

MatFile::MatFile(std::string path) : path_(std::move(path)), tmp_(path_ + ".tmp." + std::to_string(::getpid())) {
  mat_ = Mat_CreateVer(tmp_.c_str(), "dydp results (MAT v5)", MAT_FT_MAT5);
  if (!mat_) throw std::runtime_error("cannot write " + tmp_);
}

MatFile::~MatFile() {
  if (mat_) {
    Mat_Close(mat_);
    std::remove(tmp_.c_str());
  }
}

void MatFile::write(matvar_t* var) {
  if (!var) throw std::runtime_error("cannot make a MAT variable for " + path_);
  const int status = Mat_VarWrite(mat_, var, MAT_COMPRESSION_NONE);
  Mat_VarFree(var);
  if (status != 0) throw std::runtime_error("error while writing " + tmp_);
}

void MatFile::matrix(const std::string& name, size_t rows, size_t cols, const std::vector<double>& column_major) {
  if (column_major.size() != rows * cols) throw std::logic_error("MatFile::matrix: size mismatch for " + name);
  write(double_matrix(name.c_str(), rows, cols, column_major.data()));
}

void MatFile::strings(const std::string& name, const std::vector<std::string>& items) {
  write(string_cell(name.c_str(), items));
}

void MatFile::json(const std::string& name, const nlohmann::ordered_json& value) { write(from_json(name.c_str(), value)); }

void MatFile::commit() {
  Mat_Close(mat_);
  mat_ = nullptr;
  std::error_code ec;
  std::filesystem::rename(tmp_, path_, ec);
  if (ec) {
    std::remove(tmp_.c_str());
    throw std::runtime_error("cannot rename " + tmp_ + " to " + path_ + ": " + ec.message());
  }
}

}  // namespace dydp::io
