// A fuzz input as a file: the readers under test take paths. One file per process, rewritten
// for every input, removed at exit; by default in the system's temporary folder, or in a folder
// the target prepared (so that relative paths in the input reach files next to it).
#pragma once

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

namespace dydp::fuzz {

class InputFile {
 public:
  explicit InputFile(const std::string& extension,
                     const std::filesystem::path& folder = std::filesystem::temp_directory_path())
      : path_((folder / ("dydp_fuzz_" + std::to_string(::getpid()) + extension)).string()) {}
  ~InputFile() { std::remove(path_.c_str()); }

  const std::string& write(const uint8_t* data, size_t size) {
    std::ofstream(path_, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data),
                                                                     static_cast<std::streamsize>(size));
    return path_;
  }

 private:
  std::string path_;
};

}  // namespace dydp::fuzz
