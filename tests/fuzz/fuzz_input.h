// Shared by the libFuzzer targets: each input is written to a file with the loader's
// extension in a private directory (the loaders read files, and resolve includes, OBJ
// meshes and glTF buffers beside them), then loaded. Bad input must end in an InputError;
// anything else -- another exception, a crash, a sanitizer report, a timeout, memory
// beyond the limit -- is a finding that libFuzzer reports and scripts/fuzz saves.
#pragma once

#include "base/error.h"

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace oprt::fuzz {

inline std::filesystem::path work_dir() {
  static const std::filesystem::path dir = [] {
    const auto d = std::filesystem::temp_directory_path() / ("oprt_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

inline std::string write_input(const std::uint8_t* data, std::size_t size, const std::string& name) {
  const std::string path = (work_dir() / name).string();
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

// Runs `load(path)`; an InputError is the expected answer to bad input.
template <typename Load>
int run(const std::uint8_t* data, std::size_t size, const std::string& name, Load load) {
  const std::string path = write_input(data, size, name);
  try {
    load(path);
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace oprt::fuzz
