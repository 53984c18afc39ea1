#include "timing/object_memory_model.h"

#include <algorithm>

namespace oprt::hw {

namespace {
Cycle ceil_div(Cycle a, Cycle b) { return (a + b - 1) / b; }
}  // namespace

ObjectMemoryModel::ObjectMemoryModel(const Arch& arch, std::uint32_t unit)
    : arch_(arch),
      unit_(unit),
      latency_(arch.memory.model == MemoryModel::latency),
      latency_cycles_(arch.memory.latency_cycles),
      bytes_per_cycle_(arch.memory.bytes_per_cycle),
      line_transfer_(ceil_div(arch.memory.cache.line_bytes, arch.memory.dram.bytes_per_cycle)),
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
}

void ObjectMemoryModel::forget_before(Cycle t) {
  port_.forget_before(t);
  channel_.forget_before(t);
}

Cycle ObjectMemoryModel::fetch(std::uint64_t line, Cycle t) {
  ++counts_.misses;
  counts_.dram_bytes += cache_.line_bytes();
  if (fill_) return fill_->fetch(line * cache_.line_bytes(), t);
  return channel_.reserve(t, line_transfer_) + dram_latency_;
}

Cycle ObjectMemoryModel::visit(const VisitStream& v, Cycle request, BurstConsumer& unit) {
  std::size_t item = 0;
  Cycle next = request;
  const std::uint64_t line_bytes = is_cache_ ? cache_.line_bytes() : 1;
  for (std::size_t b = 0; b < v.bursts.size(); ++b) {
    const VisitStream::Burst& burst = v.bursts[b];
    const Cycle r = next;
    arrive_.resize(burst.items);
    // On-chip: the burst streams from `stream` on (the port's first free time after the latency).
    Cycle stream = r;
    if (latency_) {
      port_.reserve(r + latency_cycles_, ceil_div(Cycle{burst.items} * burst.item_bytes, bytes_per_cycle_), &stream);
    }
    std::uint64_t line = ~std::uint64_t{0};
    Cycle line_ready = 0;
    for (std::uint32_t j = 0; j < burst.items; ++j) {
      Cycle a = latency_ ? stream + ceil_div(Cycle{j + 1} * burst.item_bytes, bytes_per_cycle_) : r;
      if (is_cache_) {
        const std::uint64_t address = burst.address + std::uint64_t{j} * burst.item_bytes;
        const std::uint64_t last = (address + burst.item_bytes - 1) / line_bytes;
        for (std::uint64_t l = address / line_bytes; l <= last; ++l) {
          if (l != line) {  // a line shared by consecutive items is looked up once
            bool hit = false;
            std::uint64_t* slot = cache_.access(l, hit);
            if (hit) {
              ++counts_.hits;
              line_ready = std::max(static_cast<Cycle>(*slot), r);
            } else {
              line_ready = fetch(l, static_cast<Cycle>(window_.slot(static_cast<std::uint64_t>(r))));
              window_.sent(static_cast<std::uint64_t>(line_ready));
              *slot = static_cast<std::uint64_t>(line_ready);
            }
            line = l;
          }
          a = std::max(a, line_ready);
        }
      }
      arrive_[j] = a;
    }
    next = unit.consume(v, b, item, arrive_.data());
    item += burst.items;
  }
  return next;
}

}  // namespace oprt::hw
