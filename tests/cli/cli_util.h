// Running the oprt command from a test: its exit status and output, scene paths, fresh
// temporary directories, and outputs compared without their wall-clock figures.
#pragma once

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <sys/wait.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

namespace oprt::test {

namespace fs = std::filesystem;

struct Result {
  int status;
  std::string output;  // stdout and stderr
};

inline Result run_oprt(const std::string& args) {
  const std::string cmd = std::string(OPRT_BINARY) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), p)) out.append(buf.data(), n);
  const int st = pclose(p);
  return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

inline std::string scene(const std::string& name) { return std::string(OPRT_SOURCE_DIR) + "/scenes/" + name; }

// Unique per process: ctest runs test cases in parallel processes.
inline fs::path temp_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("oprt_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

inline nlohmann::json stats(const fs::path& dir, const std::string& file = "stats.json") {
  std::ifstream in(dir / file);
  return nlohmann::json::parse(in);
}

inline std::string bytes_of(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// A statistics file without what the wall clock and the host decide (wall times, rates, the
// thread count): what must be the same, bit for bit, however the run was scheduled.
inline nlohmann::json without_wall_clock(nlohmann::json j) {
  if (j.is_object()) {
    for (const char* k : {"wall_s", "rays_per_wall_s", "rays_per_s", "build_s", "threads"}) j.erase(k);
    for (auto& [k, v] : j.items()) v = without_wall_clock(v);
  } else if (j.is_array()) {
    for (auto& v : j) v = without_wall_clock(v);
  }
  return j;
}

}  // namespace oprt::test
