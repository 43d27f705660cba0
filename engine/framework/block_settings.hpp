// Non-numeric configuration handed to a block factory (widths, file names, signs, model names),
// each value remembering where it was written so a block can report bad values by file and line.
#pragma once

#include <map>
#include <set>
#include <string>
#include <vector>

#include "engine/framework/numbers.hpp"

namespace dydp::engine {

struct SettingSpec {
  std::string name;
  std::string description;
  std::string default_value;  ///< empty and required = true: must be given
  bool required = false;
};

class BlockSettings {
 public:
  struct Value {
    std::vector<std::string> items;  ///< one item for a scalar, several for a list
    bool is_list = false;
    int line = 0;
    std::string file;  ///< where it was written when not the block's file (a subsystem instance's value)
  };

  BlockSettings(std::string block_name, std::string file, int block_line)
      : block_(std::move(block_name)), file_(std::move(file)), line_(block_line) {}

  void set(const std::string& name, Value v) { values_[name] = std::move(v); }
  bool has(const std::string& name) const { return values_.count(name) != 0; }

  std::string text(const std::string& name) const;
  int integer(const std::string& name) const;
  double number(const std::string& name) const;
  std::vector<double> numbers(const std::string& name) const;
  std::vector<std::string> texts(const std::string& name) const;

  /// A path relative to the scene file's folder, as an absolute or scene-relative path. The
  /// setting is remembered as one that names a file (files_read).
  std::string path(const std::string& name) const;
  /// The settings the block read as paths (a recording, a table): an FMU export bundles their files.
  const std::set<std::string>& files_read() const { return files_read_; }

  /// Throws InputError at the setting's line ("file:line: block.name: message").
  [[noreturn]] void fail(const std::string& name, const std::string& message) const;
  /// Line where the setting was written (the block's line for a default or an unknown name).
  int line(const std::string& name) const;
  /// File of line(name).
  const std::string& file(const std::string& name) const;

  const std::string& block_name() const { return block_; }
  const std::string& file() const { return file_; }

 private:
  const Value& get(const std::string& name) const;
  std::string block_, file_;
  int line_;
  std::map<std::string, Value> values_;
  mutable std::set<std::string> files_read_;  ///< setting names; the block reads them while it is made
};

}  // namespace dydp::engine
