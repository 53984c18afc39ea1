// Every path a run writes, checked before anything is loaded or written: a folder where a
// file goes, a device, a pipe, a place that cannot be written, or two outputs on one path
// end the run at once with exit status 2 and the option named (an InputError). oprt only
// ever replaces regular files: each output is written under a temporary name of its own
// (ref/image.h temporary_path) and renamed over the old file when complete.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace oprt {

class OutputPlan {
 public:
  // A folder the run writes files into (--out), and the names it writes there; `frames`:
  // frame_NNNN.exr and .png for each frame in [first, last], when known.
  void folder(const std::string& option, const std::string& path, std::vector<std::string> names);
  void frames(int first, int last) { frames_ = {first, last}; }
  // A file the run writes (--vcd, --timeline), with the files written beside it.
  void file(const std::string& option, const std::string& path, std::vector<std::string> beside = {});
  // A file the run reads (the scene, the architecture file): never an output.
  void input(const std::string& what, const std::string& path);

  // Throws InputError(option, path, problem) for the first output that cannot be written as
  // asked. Reads the file system only (stat, access, and the listing of an existing --out).
  void check() const;

  // Creates the output folders (after check()); throws InputError(option, path, problem)
  // for one that cannot be created.
  void create_folders() const;

 private:
  struct Output {
    std::string option, path;
    bool folder;
    std::vector<std::string> names;  // a folder's files; a file's companions beside it
  };
  std::vector<Output> outputs_;
  std::vector<std::pair<std::string, std::string>> inputs_;
  std::optional<std::pair<int, int>> frames_;
};

// The files `--vcd PATH` writes beside the trace: GTKWave's save file and its filters.
std::vector<std::string> trace_companions(const std::string& path);

}  // namespace oprt
