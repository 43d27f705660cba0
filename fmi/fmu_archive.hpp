// The FMU's zip archive (FMI 3.0, 2.5 "FMU Distribution"), written with libzip: entries from
// memory or from files, the archive written beside its destination and renamed onto it, so
// that a failed export leaves nothing half-written. Reading back (extract) serves importers.
#pragma once

#include <string>
#include <vector>

namespace dydp::fmi {

struct ArchiveEntry {
  std::string name;         ///< path inside the archive, '/'-separated
  std::string content;      ///< the bytes, when source_file is empty
  std::string source_file;  ///< else: the file whose bytes go in
  bool compress = true;     ///< false: stored as it is (the shared objects: deflating them is slow)
};

/// Writes `entries` to `path` atomically. Throws std::runtime_error naming the file.
void write_archive(const std::string& path, const std::vector<ArchiveEntry>& entries);

/// Unpacks the archive at `path` into the folder `dir` (made if missing); refuses entries whose
/// names leave it. Throws std::runtime_error.
void extract_archive(const std::string& path, const std::string& dir);

/// The names of the archive's entries, in its order.
std::vector<std::string> archive_entries(const std::string& path);

}  // namespace dydp::fmi
