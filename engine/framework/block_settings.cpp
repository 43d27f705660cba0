#include "engine/framework/block_settings.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "engine/framework/errors.hpp"

namespace dydp::engine {

int BlockSettings::line(const std::string& name) const {
  const auto it = values_.find(name);
  return it == values_.end() || it->second.line <= 0 ? line_ : it->second.line;
}

const std::string& BlockSettings::file(const std::string& name) const {
  const auto it = values_.find(name);
  return it == values_.end() || it->second.file.empty() ? file_ : it->second.file;
}

const BlockSettings::Value& BlockSettings::get(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end())
    throw InputError(file_, line_, block_ + "." + name, "required setting is missing");
  return it->second;
}

void BlockSettings::fail(const std::string& name, const std::string& message) const {
  auto it = values_.find(name);
  throw InputError(file(name), it == values_.end() ? line_ : it->second.line, block_ + "." + name,
                   message);
}

std::string BlockSettings::text(const std::string& name) const {
  const Value& v = get(name);
  if (v.is_list || v.items.size() != 1) fail(name, "expected a single value");
  return v.items.front();
}

int BlockSettings::integer(const std::string& name) const {
  double x = 0;
  if (!parse_number(text(name), x) || x != std::floor(x) || std::fabs(x) > 1e9)
    fail(name, "expected an integer, got '" + text(name) + "'");
  return static_cast<int>(x);
}

double BlockSettings::number(const std::string& name) const {
  double x = 0;
  if (!parse_number(text(name), x)) fail(name, "malformed number '" + text(name) + "'");
  return x;
}

std::vector<double> BlockSettings::numbers(const std::string& name) const {
  std::vector<double> out;
  for (const std::string& item : get(name).items) {
    double x = 0;
    if (!parse_number(item, x)) fail(name, "malformed number '" + item + "'");
    out.push_back(x);
  }
  return out;
}

std::vector<std::string> BlockSettings::texts(const std::string& name) const {
  return get(name).items;
}

std::string BlockSettings::path(const std::string& name) const {
  std::filesystem::path p(text(name));
  files_read_.insert(name);
  if (p.is_absolute()) return p.string();
  return (std::filesystem::path(file(name)).parent_path() / p).lexically_normal().string();
}

}  // namespace dydp::engine
