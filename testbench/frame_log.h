// A run's per-frame statistics as one JSON document, {...header..., "frames": [...]}, written
// once, when the run ends (or is stopped), from the frames spooled to a hidden temporary file
// as they complete: time and memory per frame stay the same however long the run, where
// rewriting the document after every frame grew with the frame number.
#pragma once

#include <cstddef>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

namespace oprt {

class FrameLog {
 public:
  explicit FrameLog(std::string path);
  ~FrameLog();  // removes the spool
  FrameLog(const FrameLog&) = delete;
  FrameLog& operator=(const FrameLog&) = delete;

  void add(const nlohmann::json& frame);
  std::size_t frames() const { return frames_; }
  // Writes the document under its final name (through a temporary, renamed when complete):
  // `head`'s members, then "frames". Nothing if no frame was added. May be called again
  // after more frames.
  void write(const nlohmann::json& head);

 private:
  std::string path_, spool_path_;
  std::ofstream spool_;
  std::size_t frames_ = 0;
};

}  // namespace oprt
