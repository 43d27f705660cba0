#include "fmi/fmu_archive.hpp"

#include <unistd.h>
#include <zip.h>

#include <filesystem>
#include <fstream>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace dydp::fmi {
namespace {

std::string zip_error(int code) {
  zip_error_t e;
  zip_error_init_with_code(&e, code);
  std::string text = zip_error_strerror(&e);
  zip_error_fini(&e);
  return text;
}

zip_t* open_for_reading(const std::string& path) {
  int code = 0;
  zip_t* z = zip_open(path.c_str(), ZIP_RDONLY, &code);
  if (!z) throw std::runtime_error(path + ": cannot open the archive: " + zip_error(code));
  return z;
}

}  // namespace

void write_archive(const std::string& path, const std::vector<ArchiveEntry>& entries) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path temp = target.parent_path() / ("." + target.filename().string() + ".part" + std::to_string(::getpid()));
  fs::remove(temp);
  int code = 0;
  zip_t* z = zip_open(temp.c_str(), ZIP_CREATE | ZIP_EXCL, &code);
  if (!z) throw std::runtime_error(path + ": cannot write the archive: " + zip_error(code));
  auto abandon = [&](const std::string& why) {
    zip_discard(z);
    fs::remove(temp);
    throw std::runtime_error(path + ": " + why);
  };
  for (const ArchiveEntry& e : entries) {
    zip_source_t* source = nullptr;
    if (e.source_file.empty()) {
      // The bytes are copied into memory libzip frees with the source.
      void* copy = std::malloc(e.content.size() ? e.content.size() : 1);
      if (!copy) abandon("out of memory");
      std::memcpy(copy, e.content.data(), e.content.size());
      source = zip_source_buffer(z, copy, e.content.size(), 1);
      if (!source) std::free(copy);
    } else {
      if (!fs::exists(e.source_file)) abandon("no file " + e.source_file + " to put in as " + e.name);
      source = zip_source_file(z, e.source_file.c_str(), 0, -1);
    }
    if (!source) abandon(std::string("cannot add ") + e.name + ": " + zip_strerror(z));
    const zip_int64_t index = zip_file_add(z, e.name.c_str(), source, ZIP_FL_OVERWRITE | ZIP_FL_ENC_UTF_8);
    if (index < 0) {
      zip_source_free(source);
      abandon(std::string("cannot add ") + e.name + ": " + zip_strerror(z));
    }
    if (zip_set_file_compression(z, static_cast<zip_uint64_t>(index), e.compress ? ZIP_CM_DEFLATE : ZIP_CM_STORE,
                                 e.compress ? 6 : 0) < 0)
      abandon(std::string("cannot set the compression of ") + e.name + ": " + zip_strerror(z));
  }
  if (zip_close(z) < 0) {
    const std::string why = zip_strerror(z);
    zip_discard(z);
    fs::remove(temp);
    throw std::runtime_error(path + ": cannot write the archive: " + why);
  }
  std::error_code ec;
  fs::rename(temp, target, ec);
  if (ec) {
    fs::remove(temp);
    throw std::runtime_error(path + ": cannot write the archive: " + ec.message());
  }
}

std::vector<std::string> archive_entries(const std::string& path) {
  zip_t* z = open_for_reading(path);
  std::vector<std::string> names;
  const zip_int64_t n = zip_get_num_entries(z, 0);
  for (zip_int64_t k = 0; k < n; ++k) names.push_back(zip_get_name(z, k, 0));
  zip_discard(z);
  return names;
}

void extract_archive(const std::string& path, const std::string& dir) {
  namespace fs = std::filesystem;
  zip_t* z = open_for_reading(path);
  std::unique_ptr<zip_t, void (*)(zip_t*)> guard(z, zip_discard);
  const fs::path root = fs::absolute(dir).lexically_normal();
  const zip_int64_t n = zip_get_num_entries(z, 0);
  for (zip_int64_t k = 0; k < n; ++k) {
    const std::string name = zip_get_name(z, k, 0);
    const fs::path out = (root / name).lexically_normal();
    const std::string rel = out.lexically_relative(root).string();
    if (rel.empty() || rel.rfind("..", 0) == 0) throw std::runtime_error(path + ": entry " + name + " leaves the folder");
    if (!name.empty() && name.back() == '/') {
      fs::create_directories(out);
      continue;
    }
    fs::create_directories(out.parent_path());
    zip_file_t* f = zip_fopen_index(z, k, 0);
    if (!f) throw std::runtime_error(path + ": cannot read entry " + name);
    std::ofstream file(out, std::ios::binary);
    char buffer[65536];
    zip_int64_t got = 0;
    while ((got = zip_fread(f, buffer, sizeof buffer)) > 0) file.write(buffer, got);
    zip_fclose(f);
    if (got < 0 || !file) throw std::runtime_error(path + ": cannot extract entry " + name);
  }
}

}  // namespace dydp::fmi
