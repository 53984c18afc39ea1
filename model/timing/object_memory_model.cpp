#include "timing/object_memory_model.h"

#include "timing/transfers.h"

#include <algorithm>

namespace oprt::timing {

namespace {
Cycle ceil_div(Cycle a, Cycle b) { return (a + b - 1) / b; }
}  // namespace

ObjectMemoryModel::ObjectMemoryModel(const Arch& arch, std::uint32_t unit)
    : arch_(arch),
      unit_(unit),
      latency_(arch.memory.model == MemoryModel::latency),
      latency_cycles_(arch.memory.latency_cycles),
      bytes_per_cycle_(arch.memory.bytes_per_cycle),
      in_order_(arch.iu.model == IuModel::serial),
      line_transfer_(dram_line_cycles(arch)),
      dram_latency_(arch.memory.dram.latency_cycles) {}

void ObjectMemoryModel::load(const MemoryLoad& l) {
  if (l.cache && !is_cache_) {  // it held its spheres whole until now: a cold cache
    const auto& c = arch_.memory.cache;
    cache_ = Cache(arch_.memory.sram_bytes, static_cast<std::uint32_t>(c.line_bytes), static_cast<std::uint32_t>(c.ways),
                   c.replacement, std::uint64_t{unit_} + 1);
    window_ = MissWindow(static_cast<std::uint32_t>(c.misses_outstanding));
  }
  is_cache_ = l.cache;
  if (is_cache_ && l.rewritten)
    for (const auto& [first, end] : *l.rewritten)
      cache_.invalidate(first / cache_.line_bytes(), (end + cache_.line_bytes() - 1) / cache_.line_bytes());
}

void ObjectMemoryModel::restart_time() {
  cache_.settle();
  window_.clear();
  port_.clear();
  channel_.clear();
  port_free_ = channel_free_ = 0;
}

void ObjectMemoryModel::forget_before(Cycle t) {
  port_.forget_before(t);
  channel_.forget_before(t);
}

Cycle ObjectMemoryModel::fetch(std::uint64_t line, Cycle t) {
  ++counts_.misses;
  counts_.dram_bytes += cache_.line_bytes();
  if (fill_) return fill_->fetch(line * cache_.line_bytes(), t);
  if (in_order_) {
    channel_free_ = std::max(channel_free_, t) + line_transfer_;
    return channel_free_ + dram_latency_;
  }
  return channel_.reserve(t, line_transfer_) + dram_latency_;
}

Cycle ObjectMemoryModel::visit(const VisitStream& v, Cycle request, BurstConsumer& unit) {
  std::size_t item = 0;
  Cycle next = request;
  for (std::size_t b = 0; b < v.bursts.size(); ++b) {
    const VisitStream::Burst& burst = v.bursts[b];
    const Cycle r = next;
    const std::uint32_t n = burst.items;
    const Cycle bytes = burst.item_bytes;
    arrive_.resize(n);
    // On-chip: at the request, or streamed from the port's first free time after the latency.
    if (latency_) {
      Cycle stream = r + latency_cycles_;
      const Cycle length = ceil_div(Cycle{n} * bytes, bytes_per_cycle_);
      if (in_order_) {
        stream = std::max(stream, port_free_);
        port_free_ = stream + length;
      } else {
        port_.reserve(stream, length, &stream);
      }
      for (std::uint32_t j = 0; j < n; ++j) arrive_[j] = stream + ceil_div(Cycle{j + 1} * bytes, bytes_per_cycle_);
    } else {
      std::fill(arrive_.begin(), arrive_.end(), r);
    }
    if (is_cache_ && n) {
      // Every line of the burst looked up once, in order, at the request; an item is there
      // when its lines are.
      const int shift = __builtin_ctzll(cache_.line_bytes());  // a power of two (arch.cpp)
      const std::uint64_t first = burst.address >> shift;
      const std::uint64_t last = (burst.address + std::uint64_t{n} * burst.item_bytes - 1) >> shift;
      line_ready_.resize(last - first + 1);
      cache_.access_lines(first, last, [&](std::uint64_t l, std::uint64_t* slot, bool hit) {
        Cycle ready;
        if (hit) {
          ++counts_.hits;
          ready = std::max(static_cast<Cycle>(*slot), r);
        } else {
          ready = fetch(l, static_cast<Cycle>(window_.slot(static_cast<std::uint64_t>(r))));
          window_.sent(static_cast<std::uint64_t>(ready));
          *slot = static_cast<std::uint64_t>(ready);
        }
        line_ready_[l - first] = ready;
      });
      std::uint64_t address = burst.address;
      for (std::uint32_t j = 0; j < n; ++j, address += burst.item_bytes) {
        const std::uint64_t lo = (address >> shift) - first, hi = ((address + burst.item_bytes - 1) >> shift) - first;
        Cycle a = arrive_[j];
        for (std::uint64_t l = lo; l <= hi; ++l) a = std::max(a, line_ready_[l]);
        arrive_[j] = a;
      }
    }
    next = unit.consume(v, b, item, arrive_.data());
    item += n;
  }
  return next;
}

}  // namespace oprt::timing
