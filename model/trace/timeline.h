// A transaction timeline in Chrome's trace-event format (JSON), which ui.perfetto.dev and
// chrome://tracing open: one track per block (the GPP, the bus, each intersection unit) and
// one slice per piece of work, with its start, its duration and what it worked on (which
// ray). Where a waveform shows levels, the timeline shows each transaction.
//
// Slices are written as they are reported, in any order (the viewers sort them), so the
// writer holds nothing but an output buffer and one open run per track (below). Work that
// takes no simulated time has no slice.
//
// Runs: most rays enter none of a unit's spheres, and the unit only tests its spheres for
// them, back to back. Such visits (run_slice) are joined while they follow each other
// without a gap into one slice with the first and last ray and the count: a 256x256 frame's
// timeline is then less than half the size, and a viewer shows the few rays that do enter a
// sphere among long blocks of sphere tests instead of millions of identical slivers.
// A window [from, to) clips what is written; a filter decides which tracks exist.
// Plain C++ (times in picoseconds).
#pragma once

#include "trace/buffered_file.h"

#include <cstdint>
#include <cstdio>
#include <functional>
#include <initializer_list>
#include <memory>
#include <string>
#include <vector>

namespace oprt {

class TimelineWriter {
 public:
  static constexpr int kNotTraced = -1;
  static constexpr std::uint64_t kNever = ~std::uint64_t{0};

  explicit TimelineWriter(std::string path);  // throws if the file cannot be created
  ~TimelineWriter();                          // without close(): the partial file is removed
  TimelineWriter(const TimelineWriter&) = delete;
  TimelineWriter& operator=(const TimelineWriter&) = delete;

  // Which tracks exist (default: all), by the block's scope and the signal group its slices
  // belong to (trace_select.h: "state" for a unit, "bus", "gpp").
  using Filter = std::function<bool(const std::string& scope, const std::string& group)>;
  void set_filter(Filter f) { filter_ = std::move(f); }
  // A track, shown as `label`, in creation order; kNotTraced if the filter leaves it out.
  int track(const std::string& scope, const std::string& group, const std::string& label);
  // Slices are clipped to [from, to) (VcdWriter::set_window's rules).
  void set_window(std::uint64_t from_ps, std::uint64_t to_ps);

  struct Arg {
    const char* key;
    std::uint64_t value;
  };
  // [start, end) on a track; nothing if the track is kNotTraced or nothing of it lies in the
  // window.
  void slice(int track, const char* name, std::uint64_t start_ps, std::uint64_t end_ps,
             std::initializer_list<Arg> args = {});
  // A visit of one ray that may be joined to the track's previous one (same name, starting
  // where it ended): written as {"ray"} alone, or as {"first_ray", "last_ray", "rays"}.
  void run_slice(int track, const char* name, std::uint64_t start_ps, std::uint64_t end_ps, std::uint64_t ray);
  // Complete the file and move it into place.
  void close();
  const std::string& path() const { return path_; }
  std::uint64_t slices() const { return slices_; }

 private:
  struct Run {
    const char* name = nullptr;  // none open
    std::uint64_t start = 0, end = 0, first = 0, last = 0, rays = 0;
  };
  void end_run(int track);
  void put(const char* s, std::size_t n) { out_->put(s, n); }
  void put(const std::string& s) { out_->put(s); }
  void put_us(std::uint64_t ps);
  void put_uint(std::uint64_t v);

  std::string path_, tmp_;
  std::unique_ptr<BufferedFile> out_;  // tmp_, renamed to path_ once closed
  Filter filter_;
  std::uint64_t from_ = 0, to_ = kNever, slices_ = 0;
  int tracks_ = 0;
  std::vector<Run> runs_;  // per track
  bool closed_ = false;
};

}  // namespace oprt
