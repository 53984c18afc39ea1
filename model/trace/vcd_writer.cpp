#include "trace/vcd_writer.h"

#include "ref/image.h"
#include "trace/wave_format.h"

#include <algorithm>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <unistd.h>

namespace oprt {

// Every buffered entry before a horizon, lane by lane: the output's unit of work.
struct VcdWriter::Batch {
  struct Segment {
    int var;
    std::size_t begin, end;  // into entries, in time order
  };
  std::vector<Entry> entries;
  std::vector<Segment> segments;
  std::uint64_t horizon = 0;  // every entry is before it
  // The dump begins in this batch, at `from`, with the values `initial` (folded changes).
  bool begins = false;
  std::uint64_t from = 0;
  std::vector<std::uint64_t> initial;
  void clear() {
    entries.clear();
    segments.clear();
    begins = false;
    initial.clear();
  }
};

// The output thread: merges each batch into time order and writes it. It alone touches the
// file after the header; the simulation side hands it batches (one may wait) and takes the
// spent ones back for reuse. An error (a full disk) stops the writing and is rethrown to
// the simulation side by rethrow_error() or finish().
class VcdWriter::Output {
 public:
  Output(std::unique_ptr<WaveFormat> format, const std::vector<Var>& vars) : format_(std::move(format)) {
    for (const Var& v : vars) counter_.push_back(v.counter);
    value_.assign(vars.size(), 0);
    written_.assign(vars.size(), 0);
    thread_ = std::thread([this] { run(); });
  }
  ~Output() {  // abandoned: stop without writing what is queued
    {
      std::lock_guard<std::mutex> lock(m_);
      queued_.reset();
      stop_ = true;
    }
    cv_.notify_all();
    if (thread_.joinable()) thread_.join();
  }

  Batch spare() {
    std::lock_guard<std::mutex> lock(m_);
    if (spare_.empty()) return {};
    Batch b = std::move(spare_.back());
    spare_.pop_back();
    return b;
  }

  // Waits while another batch is queued: the output holds at most two.
  void submit(Batch&& b) {
    std::unique_lock<std::mutex> lock(m_);
    cv_.wait(lock, [&] { return !queued_; });
    queued_ = std::move(b);
    cv_.notify_all();
  }

  void rethrow_error() {
    std::lock_guard<std::mutex> lock(m_);
    if (error_) std::rethrow_exception(error_);
  }

  // After the last batch: wait for it, end the dump and complete the file. Returns the
  // last time written.
  std::uint64_t finish(std::uint64_t end) {
    {
      std::unique_lock<std::mutex> lock(m_);
      cv_.wait(lock, [&] { return !queued_ && !busy_; });
      stop_ = true;
    }
    cv_.notify_all();
    thread_.join();
    if (error_) std::rethrow_exception(error_);
    const std::uint64_t last = std::max(end, last_time_);
    format_->finish(last);
    return last;
  }

 private:
  void run() {
    for (;;) {
      Batch b;
      {
        std::unique_lock<std::mutex> lock(m_);
        cv_.wait(lock, [&] { return queued_ || stop_; });
        if (!queued_) return;
        b = std::move(*queued_);
        queued_.reset();
        busy_ = true;
      }
      cv_.notify_all();
      try {
        if (!error_) merge(b);
      } catch (...) {
        std::lock_guard<std::mutex> lock(m_);
        error_ = std::current_exception();
      }
      b.clear();
      {
        std::lock_guard<std::mutex> lock(m_);
        busy_ = false;
        spare_.push_back(std::move(b));
      }
      cv_.notify_all();
    }
  }

  void begin_dump(std::uint64_t at) {
    format_->time(at);
    for (std::size_t v = 0; v < value_.size(); ++v) {
      format_->value(static_cast<int>(v), value_[v]);
      written_[v] = value_[v];
    }
    started_ = true;
    last_time_ = at;
  }

  // Each entry as a key (time - base) << 17 | segment, put in time order by one counting
  // pass over coarse time buckets and a sort within each bucket (a few keys); then each key
  // applies its entry and the file gets the values that changed. Segments are in variable
  // order, so keys of one time come in declaration order. Linear in the entries, where a
  // heap over the variables costs a logarithm and a mispredicted branch per level for each.
  void merge(Batch& b) {
    if (b.begins) value_ = b.initial;
    cursor_.resize(b.segments.size());
    for (std::size_t i = 0; i < b.segments.size(); ++i) cursor_[i] = b.segments[i].begin;
    for (bool all = false; !all;) {
      std::uint64_t base = kNever;
      for (std::size_t i = 0; i < b.segments.size(); ++i)
        if (cursor_[i] < b.segments[i].end) base = std::min(base, b.entries[cursor_[i]].time);
      if (base == kNever) break;
      // A span too long for the key's 47 bits of time (hours of simulated time): in steps.
      all = b.horizon - base <= kSpan;
      step(b, base, all ? b.horizon : base + kSpan, all);
    }
    if (!started_ && b.begins) begin_dump(b.from);
  }

  static constexpr std::uint64_t kSpan = std::uint64_t{1} << 47;
  static constexpr int kSegmentBits = 17;

  void step(Batch& b, std::uint64_t base, std::uint64_t h, bool all) {
    auto end_of = [&](std::size_t i) {  // the segment's entries before h
      if (all) return b.segments[i].end;
      std::size_t k = cursor_[i];
      while (k < b.segments[i].end && b.entries[k].time < h) ++k;
      return k;
    };
    ends_.resize(b.segments.size());
    std::size_t n = 0;
    for (std::size_t i = 0; i < b.segments.size(); ++i) n += (ends_[i] = end_of(i)) - cursor_[i];
    int bucket_bits = 0;
    while ((std::size_t{1} << bucket_bits) < n) ++bucket_bits;
    int span_bits = 0;
    while (span_bits < 64 && ((h - base - 1) >> span_bits)) ++span_bits;
    const int shift = std::max(0, span_bits - bucket_bits);
    const std::size_t buckets = std::size_t{1} << bucket_bits;
    starts_.assign(buckets + 1, 0);
    for (std::size_t i = 0; i < b.segments.size(); ++i)
      for (std::size_t k = cursor_[i]; k < ends_[i]; ++k) ++starts_[((b.entries[k].time - base) >> shift) + 1];
    for (std::size_t k = 1; k <= buckets; ++k) starts_[k] += starts_[k - 1];
    keys_.resize(n);
    for (std::size_t i = 0; i < b.segments.size(); ++i)
      for (std::size_t k = cursor_[i]; k < ends_[i]; ++k) {
        const std::uint64_t dt = b.entries[k].time - base;
        keys_[starts_[dt >> shift]++] = dt << kSegmentBits | i;
      }
    for (std::size_t k = 0, begin = 0; k < buckets; begin = starts_[k++]) {
      const std::size_t size = starts_[k] - begin;
      if (size > 16) {
        std::sort(keys_.begin() + static_cast<std::ptrdiff_t>(begin),
                  keys_.begin() + static_cast<std::ptrdiff_t>(starts_[k]));
      } else {  // most buckets hold a key or two
        for (std::size_t i = begin + 1; i < starts_[k]; ++i)
          for (std::size_t j = i; j > begin && keys_[j] < keys_[j - 1]; --j) std::swap(keys_[j], keys_[j - 1]);
      }
    }
    constexpr std::uint64_t kSegment = (std::uint64_t{1} << kSegmentBits) - 1;
    for (std::size_t i = 0; i < n;) {
      const std::uint64_t dt = keys_[i] >> kSegmentBits, t = base + dt;
      if (!started_ && b.begins && t > b.from) begin_dump(b.from);
      bool stamped = false;
      for (; i < n && keys_[i] >> kSegmentBits == dt; ++i) {
        const std::size_t seg = keys_[i] & kSegment;
        const int v = b.segments[seg].var;
        const std::uint64_t x = b.entries[cursor_[seg]++].value;
        value_[v] = counter_[v] ? value_[v] + x : x;
        // A counter's other lane at the same time: the next key; write once, after both.
        if (i + 1 < n && keys_[i + 1] >> kSegmentBits == dt && b.segments[keys_[i + 1] & kSegment].var == v) continue;
        if (!started_ || value_[v] == written_[v]) continue;  // before the dump: part of its first values
        if (!stamped) {
          format_->time(t);
          last_time_ = t;
          stamped = true;
        }
        format_->value(v, value_[v]);
        written_[v] = value_[v];
      }
      if (!started_ && b.begins && t == b.from) begin_dump(b.from);
    }
  }

  std::unique_ptr<WaveFormat> format_;
  std::thread thread_;
  std::mutex m_;
  std::condition_variable cv_;
  std::optional<Batch> queued_;
  std::vector<Batch> spare_;
  bool busy_ = false, stop_ = false;
  std::exception_ptr error_;
  // Merge state (the output thread's own).
  std::vector<bool> counter_;
  std::vector<std::uint64_t> value_, written_;
  std::vector<std::size_t> cursor_, ends_;  // per segment: its next entry, the end of this step's
  std::vector<std::uint64_t> keys_;          // (time - base) << kSegmentBits | segment
  std::vector<std::size_t> starts_;  // per time bucket: where its keys go
  bool started_ = false;
  std::uint64_t last_time_ = 0;
};

VcdWriter::VcdWriter(std::string path) : path_(std::move(path)) {
  tmp_ = temporary_path(path_);
}

VcdWriter::~VcdWriter() {
  if (closed_) return;
  out_.reset();  // abandoned (an error): leave no partial file behind
  std::remove(tmp_.c_str());
  for (const std::string& f : wave_side_files(path_, tmp_)) std::remove(f.c_str());
}

int VcdWriter::declare(const std::string& scope, const std::string& name, int width, bool counter) {
  if (changed_ || out_) throw std::logic_error("VcdWriter: variable declared after the first change");
  if (width < 1 || width > 64) throw std::logic_error("VcdWriter: " + name + ": width must be 1 to 64");
  if (vars_.size() >= 0xffff) throw std::logic_error("VcdWriter: more than 65535 variables");
  if (filter_ && !filter_(scope, name)) return kNotTraced;
  Var v;
  v.scope = scope;
  v.name = name;
  v.width = width;
  v.counter = counter;
  vars_.push_back(std::move(v));
  return static_cast<int>(vars_.size() - 1);
}

int VcdWriter::add(const std::string& scope, const std::string& name, int width) {
  return declare(scope, name, width, false);
}

int VcdWriter::add_counter(const std::string& scope, const std::string& name, int width) {
  return declare(scope, name, width, true);
}

// The file and its header, and the output thread.
void VcdWriter::first_change() {
  changed_ = true;
  if (out_) return;
  std::unique_ptr<WaveFormat> format = open_wave_format(path_, tmp_);
  std::vector<WaveVar> vars;
  for (const Var& v : vars_) vars.push_back({v.scope, v.name, v.width});
  format->declare(vars);
  out_ = std::make_unique<Output>(std::move(format), vars_);
}

void VcdWriter::too_early(int var, std::uint64_t t) const {
  throw std::logic_error("VcdWriter: " + vars_[var].scope + "." + vars_[var].name + " changed at " + std::to_string(t) +
                         " ps, before the trace's horizon " + std::to_string(flushed_) + " ps");
}

// A counter's pushes and pops come from different processes, each in its own time order:
// each lane takes one stream (the lane whose last entry is the latest not after t), so
// appends stay appends.

void VcdWriter::fold(Var& x, std::uint64_t t, std::uint64_t v) {
  if (x.counter) {
    x.folded += v;
  } else if (t >= x.folded_time) {  // the latest change before the window; of equal times the last reported
    x.folded = v;
    x.folded_time = t;
  }
  latest_folded_ = std::max(latest_folded_, t);
  any_folded_ = true;
}

// Out of order (rare: a bus arbiter granting a late request an earlier slot).
void VcdWriter::insert(Lane& lane, std::uint64_t t, std::uint64_t v, bool counter) {
  const auto at = std::lower_bound(lane.e.begin() + static_cast<std::ptrdiff_t>(lane.head), lane.e.end(), t,
                                   [](const Entry& e, std::uint64_t x) { return e.time < x; });
  if (at != lane.e.end() && at->time == t) {
    at->value = counter ? at->value + v : v;
    return;
  }
  lane.e.insert(at, {t, v});
  peak_ = std::max(peak_, ++pending_);
}

// From inside the simulation (a module reporting a change): an output error waits for the
// testbench's next flush_before or close to be reported.
void VcdWriter::auto_flush() {
  if (horizon_) {
    const std::uint64_t h = horizon_();
    if (h > flushed_) seal(h, false);
  }
  next_flush_ = pending_ + kFlushEvery;
}

bool VcdWriter::over_budget() {
  if (pending_ <= budget_) return false;
  auto_flush();
  return pending_ > budget_;
}

std::size_t VcdWriter::count_before(std::uint64_t t) const {
  std::size_t n = 0;
  for (const Var& x : vars_)
    for (const Lane& l : x.lanes) {
      const auto first = l.e.begin() + static_cast<std::ptrdiff_t>(l.head);
      n += static_cast<std::size_t>(
          std::lower_bound(first, l.e.end(), t, [](const Entry& e, std::uint64_t v) { return e.time < v; }) - first);
    }
  return n;
}

// In batches of at most kMaxBatch entries (what the output holds is at most two batches):
// a larger flush (a frame's end) is cut at earlier horizons.
void VcdWriter::seal(std::uint64_t horizon, bool begin) {
  const std::uint64_t h = std::min(horizon, to_);
  if (h <= flushed_ && !(begin && !begun_)) return;
  if (!out_) first_change();
  for (;;) {
    std::uint64_t cut = h;
    if (pending_ > kMaxBatch && count_before(h) > kMaxBatch) {
      std::uint64_t lo = flushed_, hi = h;  // count_before(lo) <= kMaxBatch < count_before(hi)
      while (hi - lo > 1) (count_before(lo + (hi - lo) / 2) <= kMaxBatch ? lo : hi) = lo + (hi - lo) / 2;
      std::uint64_t earliest = kNever;  // at least one time per batch: a time holds at most two entries per variable
      for (const Var& x : vars_)
        for (const Lane& l : x.lanes)
          if (!l.empty()) earliest = std::min(earliest, l.e[l.head].time);
      cut = std::max(lo, earliest + 1);
    }
    hand_on(cut, begin && cut == h);
    if (cut == h) return;
  }
}

void VcdWriter::hand_on(std::uint64_t h, bool begin) {
  Batch b = out_->spare();
  b.horizon = std::max(h, flushed_);
  for (std::size_t v = 0; v < vars_.size(); ++v)
    for (Lane& l : vars_[v].lanes) {
      const auto first = l.e.begin() + static_cast<std::ptrdiff_t>(l.head);
      const auto end =
          std::lower_bound(first, l.e.end(), h, [](const Entry& e, std::uint64_t t) { return e.time < t; });
      if (end == first) continue;
      const std::size_t at = b.entries.size();
      b.entries.insert(b.entries.end(), first, end);
      b.segments.push_back({static_cast<int>(v), at, b.entries.size()});
      pending_ -= static_cast<std::size_t>(end - first);
      l.head = static_cast<std::size_t>(end - l.e.begin());
      if (2 * l.head >= l.e.size()) {  // drop the consumed half
        l.e.erase(l.e.begin(), l.e.begin() + static_cast<std::ptrdiff_t>(l.head));
        l.head = 0;
        // and the room a lane no longer needs: lanes peak at different times, their
        // capacities would add up to several times what is ever buffered at once
        if (l.e.capacity() > 1024 && l.e.capacity() > 4 * l.e.size()) l.e.shrink_to_fit();
      }
    }
  if (!begun_ && (h > from_ || begin)) {
    b.begins = true;
    b.from = from_;
    for (const Var& x : vars_) b.initial.push_back(x.folded);
    begun_ = true;
    dump_start_ = from_;
  }
  flushed_ = std::max(flushed_, h);
  out_->submit(std::move(b));
}

void VcdWriter::flush_before(std::uint64_t horizon) {
  seal(horizon, false);
  if (out_) out_->rethrow_error();
}

void VcdWriter::fold_before(std::uint64_t t) {
  for (Var& x : vars_)
    for (Lane& l : x.lanes)
      for (; !l.empty() && l.e[l.head].time < t; ++l.head, --pending_) fold(x, l.e[l.head].time, l.e[l.head].value);
}

void VcdWriter::set_window(std::uint64_t from, std::uint64_t to) {
  if (from >= from_ ? from != from_ && begun_ : begun_ || (any_folded_ && latest_folded_ > from))
    throw std::logic_error("VcdWriter: the window cannot start at " + std::to_string(from) + " ps any more");
  if (to > to_ && changed_)
    throw std::logic_error("VcdWriter: the window can only end earlier once changes are reported");
  if (to < to_) discard_from(to);
  to_ = to;
  if (from > from_) fold_before(from);
  from_ = from;
}

void VcdWriter::discard_from(std::uint64_t t) {
  if (begun_ && t < flushed_) throw std::logic_error("VcdWriter: cannot discard changes already written");
  for (Var& x : vars_)
    for (Lane& l : x.lanes) {
      const auto at = std::lower_bound(l.e.begin() + static_cast<std::ptrdiff_t>(l.head), l.e.end(), t,
                                       [](const Entry& e, std::uint64_t v) { return e.time < v; });
      pending_ -= static_cast<std::size_t>(l.e.end() - at);
      l.e.erase(at, l.e.end());
    }
}

std::vector<std::pair<std::string, int>> VcdWriter::variables() const {
  std::vector<std::pair<std::string, int>> n;
  for (const Var& v : vars_) n.emplace_back(v.scope.empty() ? v.name : v.scope + "." + v.name, v.width);
  return n;
}

void VcdWriter::close(std::uint64_t end_ps) {
  if (closed_) return;
  const std::uint64_t end = std::min(end_ps, to_);
  if (!begun_ && from_ > end) from_ = end;  // the window opens after the run: the values at its end
  if (end != kNever && !(begun_ && end + 1 < flushed_)) discard_from(end + 1);
  seal(kNever, true);
  dump_end_ = out_->finish(end);
  out_.reset();
  std::filesystem::rename(tmp_, path_);
  closed_ = true;
}

}  // namespace oprt
