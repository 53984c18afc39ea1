// The file formats a waveform trace is written in: VCD text, and GTKWave's compressed FST
// (through GTKWave's own fstapi, third_party/fstapi). VcdWriter (vcd_writer.h) decides what to
// write and when; a format only encodes value changes handed to it in time order.
// Plain C++ (times in picoseconds).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace oprt {

struct WaveVar {
  std::string scope;  // dotted module path, "testbench.engine.iu3": nested scopes in the file
  std::string name;
  int width;
};

class WaveFormat {
 public:
  virtual ~WaveFormat() = default;
  // Every variable, once, before the first time; a variable's index is its handle below.
  virtual void declare(const std::vector<WaveVar>& vars) = 0;
  virtual void time(std::uint64_t t) = 0;  // increasing
  virtual void value(int var, std::uint64_t v) = 0;
  // End the dump at `end` (after the last time) and complete the file; throws if it cannot
  // be written.
  virtual void finish(std::uint64_t end) = 0;
};

// True if `path` names an FST file (it ends in .fst).
bool is_fst_path(const std::string& path);
// Writes `file` (a temporary name the caller renames into place) in the format `path` asks
// for. Throws std::runtime_error if the file cannot be created.
std::unique_ptr<WaveFormat> open_wave_format(const std::string& path, const std::string& file);
// Files beside `file` the format may leave behind if it is abandoned (FST's hierarchy file).
std::vector<std::string> wave_side_files(const std::string& path, const std::string& file);

}  // namespace oprt
