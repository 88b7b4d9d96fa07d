// Shared by the libFuzzer targets: the program reads files by path, so each input is written to a file
// in a private temporary folder (one per process; libFuzzer's -fork and -jobs start one process each)
// and read from there the way pmr reads it.
#pragma once
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "pmr/input_files.h"

namespace pmr::fuzz {

// A new folder under $TMPDIR (or /tmp), removed when the process exits normally.
inline const std::string& folder() {
  static const std::string dir = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::string pattern = std::string(tmp && *tmp ? tmp : "/tmp") + "/pmr-fuzz-XXXXXX";
    if (!mkdtemp(pattern.data())) {
      std::perror("mkdtemp");
      std::abort();
    }
    static std::string to_remove = pattern;
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(to_remove, ec);
    });
    return pattern;
  }();
  return dir;
}

inline void write_file(const std::string& path, const uint8_t* data, size_t size) {
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f || (size && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
    std::perror(path.c_str());
    std::abort();
  }
}

inline void write_file(const std::string& path, const std::string& text) {
  write_file(path, reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

// Budgets far below the defaults, so that an input the budgets allow stays fast to load; the budget
// checks themselves run the same code at any size.
inline InputLimits small_limits() {
  InputLimits limits;
  limits.file_bytes = uint64_t(1) << 20;
  limits.texture_pixels = uint64_t(1) << 20;
  limits.vertex_data = uint64_t(64) << 20;
  limits.animation_data = uint64_t(16) << 20;
  limits.json_bytes = uint64_t(1) << 20;
  return limits;
}

}  // namespace pmr::fuzz
