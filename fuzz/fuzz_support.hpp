// What the fuzz targets share: a private folder for the files that carry an input
// into the code under test (the jobs-file and image paths read files, not memory).
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

namespace wt::fuzz {

// A folder of this process's own, made on first use and removed at exit.
inline const std::string& temp_dir() {
  // Never freed, so that it outlives the handler that removes the folder at exit.
  static const std::string* dir = [] {
    std::string pattern = (std::filesystem::temp_directory_path() / "wavetrace-fuzz-XXXXXX").string();
    if (!::mkdtemp(pattern.data())) {
      std::perror("wavetrace fuzz: mkdtemp");
      std::abort();
    }
    return new std::string(pattern);
  }();
  static const bool cleanup = std::atexit([] { std::filesystem::remove_all(*dir); }) == 0;
  (void)cleanup;
  return *dir;
}

// Writes the input to NAME in temp_dir() and returns its path.
inline std::string write_input(const char* name, const uint8_t* data, size_t size) {
  std::string path = temp_dir() + "/" + name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f || (size && std::fwrite(data, 1, size, f) != size) || std::fclose(f) != 0) {
    std::perror(("wavetrace fuzz: writing " + path).c_str());
    std::abort();
  }
  return path;
}

}  // namespace wt::fuzz
