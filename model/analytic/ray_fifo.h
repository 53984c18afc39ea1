// The analytic level's ray FIFOs (hw/ray_fifo.h): per unit, the rays written into it and when
// the unit popped each. A write needs room: with depth d, the pop of the ray written d writes
// before it (`unknown` while the unit has yet to pop that ray). The peak occupancy is counted
// over the run.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace oprt::analytic {

class AnalyticFifos {
 public:
  using Cycles = std::uint64_t;
  static constexpr Cycles unknown = ~Cycles{0} - 1;

  AnalyticFifos(std::size_t units, unsigned depth, std::vector<std::uint64_t>& peak)
      : depth_(depth), pushes_(units, 0), pops_(depth ? units : 0), queued_(units), peak_(peak) {
    peak_.resize(units, 0);
  }

  // When unit u's FIFO has room for one more write.
  Cycles room(std::uint32_t u) const {
    if (!depth_ || pushes_[u] < depth_) return 0;
    const std::uint64_t k = pushes_[u] - depth_;
    return k < pops_[u].size() ? pops_[u][k] : unknown;
  }
  bool bounded() const { return depth_ != 0; }
  void pushed(std::uint32_t u) { ++pushes_[u]; }
  // Unit u popped the ray that arrived at `avail`, at `start`.
  void popped(std::uint32_t u, Cycles avail, Cycles start) {
    peak_[u] = std::max<std::uint64_t>(peak_[u], queued_[u].occupancy_after_push(avail, start));
    if (depth_) pops_[u].push_back(start);
  }
  std::uint64_t pushes(std::uint32_t u) const { return pushes_[u]; }

 private:
  // Occupancy in time: pop times of the rays still queued at the latest push. A unit pops in
  // push order, so they only grow: a ring of them, doubled when full.
  struct PopTimes {
    std::vector<Cycles> t = std::vector<Cycles>(8);
    std::size_t head = 0, size = 0;  // t.size() is a power of two
    std::size_t occupancy_after_push(Cycles at, Cycles pop) {  // rays it holds once this one is in
      const std::size_t mask = t.size() - 1;
      if (pop <= at) size = 0;  // popped at once: every ray before it has left (pops come in order)
      while (size && t[head] <= at) head = (head + 1) & mask, --size;
      if (size == t.size()) {
        std::vector<Cycles> bigger(2 * t.size());
        for (std::size_t i = 0; i < size; ++i) bigger[i] = t[(head + i) & mask];
        t.swap(bigger);
        head = 0;
      }
      t[(head + size) & (t.size() - 1)] = pop;
      return ++size;
    }
  };
  const unsigned depth_;
  std::vector<std::uint64_t> pushes_;
  std::vector<std::vector<Cycles>> pops_;
  std::vector<PopTimes> queued_;
  std::vector<std::uint64_t>& peak_;  // per unit, over the run
};

}  // namespace oprt::analytic
