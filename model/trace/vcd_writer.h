// A waveform trace for GTKWave, written from timestamped value changes: VCD text, or
// GTKWave's compressed FST when the path ends in .fst (wave_format.h).
//
// Changes may be reported out of time order (a unit reports the phases of a ray when it
// starts it; units whose timing nothing else observes run ahead of simulation time), so they
// are buffered and written in time order up to a horizon no process can report behind: the
// current simulation time, which every process's local time is at or after. Of several
// changes of one variable at one time only the last is written, and variables in
// declaration order: the file depends only on the values at each time, not on the order
// they were reported in.
//
// Memory and time. Each variable keeps its buffered changes in time order, one entry per
// distinct time (a counter's pushes and pops in two lanes, each in order), so reporting a
// change is an append. Every kFlushEvery new entries the writer hands everything before the
// horizon (set_horizon: simulation time) to its output thread, which merges it into time
// order, encodes it and writes it while the simulation goes on; at most one such batch waits
// for it. What the simulation side holds is what lies ahead of simulation time. A process
// that runs ahead of simulation time (an intersection unit with nothing to observe it,
// local_clock.h) asks over_budget() after each ray and, if the writer holds more than its
// budget, lets simulation time catch up: the buffer stays within the budget plus one ray's
// changes per unit, whatever the frame size (docs/results.md has the figures).
//
// A window [from, to) limits what is written: the dump starts at `from` with every
// variable's value then (changes before it are folded into those values as they are
// reported, without buffering) and ends at `to` (later changes are dropped). A filter
// decides which variables are traced at all. Plain C++ (times in picoseconds).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace oprt {

class WaveFormat;

class VcdWriter {
 public:
  static constexpr int kNotTraced = -1;  // add()'s handle for a variable the filter leaves out
  static constexpr std::uint64_t kNever = ~std::uint64_t{0};
  static constexpr std::size_t kFlushEvery = 1 << 16;  // new entries between flushes
  static constexpr std::size_t kDefaultBudget = 1 << 17;  // entries (16 bytes each)
  static constexpr std::size_t kMaxBatch = 1 << 17;       // entries handed to the output at once

  explicit VcdWriter(std::string path);
  ~VcdWriter();  // without close(): the partial file is removed
  VcdWriter(const VcdWriter&) = delete;
  VcdWriter& operator=(const VcdWriter&) = delete;

  // Which variables are traced (default: all); set before the first add().
  using Filter = std::function<bool(const std::string& scope, const std::string& name)>;
  void set_filter(Filter f) { filter_ = std::move(f); }
  // Declare a variable before the first change; returns its handle, or kNotTraced (changes
  // to kNotTraced are ignored).
  int add(const std::string& scope, const std::string& name, int width);
  // A counter: its value is the sum of the deltas reported up to each time, in time order
  // (a FIFO's occupancy, whose pushes and pops are reported by different processes).
  int add_counter(const std::string& scope, const std::string& name, int width);
  void change(int var, std::uint64_t time_ps, std::uint64_t value);
  void change_by(int var, std::uint64_t time_ps, std::int64_t delta);

  // Write only [from, to). `from` may move later at any time, or earlier down to the latest
  // change already folded before it (the testbench opens the window when the first traced
  // frame starts); `to` may move earlier.
  void set_window(std::uint64_t from_ps, std::uint64_t to_ps);
  std::uint64_t window_from() const { return from_; }
  std::uint64_t window_to() const { return to_; }
  // Where no process can report behind any more (simulation time): lets the writer flush
  // within a frame.
  void set_horizon(std::function<std::uint64_t()> now_ps) { horizon_ = std::move(now_ps); }
  void set_budget(std::size_t entries) { budget_ = entries; }
  // Holds more than its budget even after flushing to the horizon: a process running ahead
  // should let simulation time catch up.
  bool over_budget();
  bool full() const { return pending_ > budget_; }  // over_budget() without trying to flush

  // Write every buffered change before `horizon_ps` (on the output thread; an output error
  // is rethrown here or by close).
  void flush_before(std::uint64_t horizon_ps);
  std::uint64_t flushed() const { return flushed_; }  // everything before this has been handed on
  // Forget buffered changes at or after t_ps (a frame abandoned when the run was stopped).
  void discard_from(std::uint64_t t_ps);
  // Write everything, end the dump at min(end_ps, to), and move the file into place.
  void close(std::uint64_t end_ps);
  const std::string& path() const { return path_; }
  // Declared (traced) variables as ("scope.name", width), in declaration order.
  std::vector<std::pair<std::string, int>> variables() const;
  // The span the file covers once closed.
  std::uint64_t dump_start() const { return dump_start_; }
  std::uint64_t dump_end() const { return dump_end_; }
  // Entries buffered now and at most so far (tests, docs/results.md).
  std::size_t buffered() const { return pending_; }
  std::size_t peak_buffered() const { return peak_; }

 private:
  struct Entry {
    std::uint64_t time, value;  // a counter's value is a delta
  };
  struct Lane {  // entries in increasing time; [head, size) are buffered
    std::vector<Entry> e;
    std::size_t head = 0;
    bool empty() const { return head == e.size(); }
  };
  struct Var {
    std::string scope, name;
    int width;
    bool counter = false;
    std::uint64_t folded = 0;       // its value before the window (reported changes folded in)
    std::uint64_t folded_time = 0;  // not a counter: time of the latest change folded
    Lane lanes[2];                  // a counter uses both, a value lane 0
  };
  struct Batch;
  class Output;

  int declare(const std::string& scope, const std::string& name, int width, bool counter);
  void first_change();
  [[noreturn]] void too_early(int var, std::uint64_t t) const;
  bool take(int var, std::uint64_t t);
  Lane& counter_lane(Var& x, std::uint64_t t);
  void put(Lane& lane, std::uint64_t t, std::uint64_t v, bool counter);
  void insert(Lane& lane, std::uint64_t t, std::uint64_t v, bool counter);
  void fold(Var& x, std::uint64_t t, std::uint64_t v);
  void fold_before(std::uint64_t t);
  void auto_flush();
  // Hand every entry before h to the output; `begin` forces the dump to begin (at close).
  void seal(std::uint64_t h, bool begin);
  void hand_on(std::uint64_t h, bool begin);  // one batch
  std::size_t count_before(std::uint64_t t) const;

  std::string path_, tmp_;
  std::unique_ptr<Output> out_;
  std::vector<Var> vars_;
  Filter filter_;
  std::function<std::uint64_t()> horizon_;
  std::uint64_t from_ = 0, to_ = kNever;
  std::uint64_t flushed_ = 0;        // every change before this has gone to the output
  std::uint64_t latest_folded_ = 0;  // the latest change folded into the values before the window
  bool any_folded_ = false;
  std::size_t pending_ = 0, peak_ = 0, budget_ = kDefaultBudget, next_flush_ = kFlushEvery;
  std::uint64_t dump_start_ = 0, dump_end_ = 0;
  bool changed_ = false;  // a change was reported: no more declarations
  bool begun_ = false;    // the dump has begun (the values at `from` went to the output)
  bool closed_ = false;
};

// Reporting a change is on every module's path: inline, an append in the common case.

// False if the change is not recorded (not traced, or after the window). The horizon rule:
// once the dump has begun, nothing may be reported before what has been handed on.
inline bool VcdWriter::take(int var, std::uint64_t t) {
  if (var < 0 || t >= to_) return false;
  if (!changed_) first_change();
  if (begun_ && t < flushed_) too_early(var, t);
  return true;
}

inline void VcdWriter::change(int var, std::uint64_t t, std::uint64_t value) {
  if (!take(var, t)) return;
  Var& x = vars_[static_cast<std::size_t>(var)];
  if (t < from_) fold(x, t, value);
  else put(x.lanes[0], t, value, false);
}

// A counter's pushes and pops each come in time order: two lanes, each in order (the first
// that takes t without an insertion; one of them normally does).
inline VcdWriter::Lane& VcdWriter::counter_lane(Var& x, std::uint64_t t) {
  Lane& a = x.lanes[0];
  Lane& b = x.lanes[1];
  const bool fits_a = a.empty() || t >= a.e.back().time;
  const bool fits_b = b.empty() || t >= b.e.back().time;
  if (fits_a && fits_b) return b.empty() || (!a.empty() && a.e.back().time >= b.e.back().time) ? a : b;
  if (fits_a) return a;
  if (fits_b) return b;
  return a.e.back().time <= b.e.back().time ? a : b;
}

inline void VcdWriter::change_by(int var, std::uint64_t t, std::int64_t delta) {
  if (!take(var, t)) return;
  Var& x = vars_[static_cast<std::size_t>(var)];
  const auto d = static_cast<std::uint64_t>(delta);  // counters: wrapping sums of deltas
  if (t < from_) fold(x, t, d);
  else put(counter_lane(x, t), t, d, true);
}

inline void VcdWriter::put(Lane& lane, std::uint64_t t, std::uint64_t v, bool counter) {
  if (lane.empty() || t > lane.e.back().time) {
    lane.e.push_back({t, v});
    if (++pending_ > peak_) peak_ = pending_;
    if (pending_ >= next_flush_) auto_flush();
  } else if (t == lane.e.back().time) {
    Entry& e = lane.e.back();
    e.value = counter ? e.value + v : v;
  } else {
    insert(lane, t, v, counter);
  }
}

}  // namespace oprt
