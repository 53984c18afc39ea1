// The shared bus's arbiter (and a DRAM channel's, and a pipelined unit's issue slots): a
// calendar of granted intervals. A request for `length` at time
// `request` is granted the first gap at or after `request` long enough to hold it. Requests
// in time order reduce to first come, first served; requests out of time order (temporal
// decoupling, the analytic level) are slotted into the gap where they belong instead of
// queueing behind every later reservation. Plain C++, on any totally ordered time type.
#pragma once

#include <algorithm>
#include <iterator>
#include <vector>

namespace oprt::timing {

template <typename Time>
class Calendar {
 public:
  // Returns the end of the granted interval.
  Time reserve(Time request, Time length, Time* start_out = nullptr) {
    // Requests in time order, the usual case: after every grant.
    if (head_ == granted_.size() || !(request < granted_.back().end)) {
      if (start_out) *start_out = request;
      const Time end = request + length;
      if (!(length > Time{})) return end;
      if (head_ < granted_.size() && granted_.back().end == request) granted_.back().end = end;
      else granted_.push_back(Interval{request, end});
      return end;
    }
    // The first interval that ends after the request; every gap before it is behind us.
    auto it = std::upper_bound(granted_.begin() + static_cast<std::ptrdiff_t>(head_), granted_.end(), request,
                               [](const Time& t, const Interval& g) { return t < g.end; });
    Time start = request;
    for (; it != granted_.end() && it->start < start + length; ++it) start = std::max(start, it->end);
    if (start_out) *start_out = start;
    const Time end = start + length;
    if (!(length > Time{})) return end;
    // `it` is the first interval starting at or after `end`; the one before it, if any, ends
    // at or before `start`. Join the new one with a neighbour it touches: requests mostly
    // come in time order and fill the calendar back to back, so it stays a few intervals long.
    const bool joins_before = it != granted_.begin() + static_cast<std::ptrdiff_t>(head_) && std::prev(it)->end == start;
    const bool joins_after = it != granted_.end() && it->start == end;
    if (joins_before && joins_after) {
      std::prev(it)->end = it->end;
      granted_.erase(it);
    } else if (joins_before) {
      std::prev(it)->end = end;
    } else if (joins_after) {
      it->start = start;
    } else {
      granted_.insert(it, Interval{start, end});
    }
    return end;
  }
  // Forget intervals that ended at or before `t` (no request can come for earlier times).
  void forget_before(Time t) {
    while (head_ < granted_.size() && !(t < granted_[head_].end)) ++head_;
    if (head_ > 64 && 2 * head_ > granted_.size()) {
      granted_.erase(granted_.begin(), granted_.begin() + static_cast<std::ptrdiff_t>(head_));
      head_ = 0;
    }
  }
  void clear() {
    granted_.clear();
    head_ = 0;
  }
  // Intervals booked (after joining neighbours), for tests.
  std::size_t intervals() const { return granted_.size() - head_; }

 private:
  struct Interval {
    Time start, end;
  };
  std::vector<Interval> granted_;  // disjoint, in time order, from head_ on
  std::size_t head_ = 0;
};

// The naive arbiter: one time, when the bus is next free; a request is granted at
// max(request, busy_until). Identical to the calendar when requests arrive in time order
// (`at`). Under temporal decoupling a request that arrives after a later-timed one queues
// behind it: contention is overstated by up to a quantum per transfer. Kept only to
// measure the error the calendar avoids (bus.lt_arbitration = "busy_until").
template <typename Time>
class BusyUntil {
 public:
  Time reserve(Time request, Time length, Time* start_out = nullptr) {
    const Time start = std::max(request, busy_until_);
    busy_until_ = start + length;
    if (start_out) *start_out = start;
    return busy_until_;
  }
  void forget_before(Time) {}
  void clear() { busy_until_ = Time{}; }

 private:
  Time busy_until_{};
};

// One of the two, chosen at construction.
template <typename Time>
class Arbiter {
 public:
  explicit Arbiter(bool naive) : naive_(naive) {}
  Time reserve(Time request, Time length, Time* start_out = nullptr) {
    return naive_ ? busy_until_.reserve(request, length, start_out) : calendar_.reserve(request, length, start_out);
  }
  void forget_before(Time t) { calendar_.forget_before(t); }

 private:
  bool naive_;
  Calendar<Time> calendar_;
  BusyUntil<Time> busy_until_;
};

}  // namespace oprt::timing
