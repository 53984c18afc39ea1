// The shared bus's arbiter: a calendar of granted intervals. A request for `length` at time
// `request` is granted the first gap at or after `request` long enough to hold it. Requests
// in time order reduce to first come, first served; requests out of time order (temporal
// decoupling, the analytic level) are slotted into the gap where they belong instead of
// queueing behind every later reservation. Plain C++, on any totally ordered time type.
#pragma once

#include <algorithm>
#include <iterator>
#include <map>

namespace oprt::hw {

template <typename Time>
class Calendar {
 public:
  // Returns the end of the granted interval.
  Time reserve(Time request, Time length, Time* start_out = nullptr) {
    Time start = request;
    auto it = granted_.upper_bound(start);
    if (it != granted_.begin()) {
      auto prev = std::prev(it);
      if (prev->second > start) start = prev->second;
    }
    for (; it != granted_.end() && it->first < start + length; ++it) start = std::max(start, it->second);
    if (length > Time{}) granted_.emplace(start, start + length);
    if (start_out) *start_out = start;
    return start + length;
  }
  // Forget intervals that ended at or before `t` (no request can come for earlier times).
  void forget_before(Time t) {
    while (!granted_.empty() && granted_.begin()->second <= t) granted_.erase(granted_.begin());
  }
  void clear() { granted_.clear(); }

 private:
  std::map<Time, Time> granted_;  // start -> end, disjoint
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

}  // namespace oprt::hw
