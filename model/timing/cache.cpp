#include "timing/cache.h"

#include <algorithm>

namespace oprt::timing {

Cache::Cache(std::uint64_t capacity, std::uint32_t line_bytes, std::uint32_t ways, CacheReplacement r, std::uint64_t seed)
    : line_bytes_(line_bytes), ways_(ways), replacement_(r), rng_(seed * 0x9E3779B97F4A7C15ull + 1) {
  sets_ = std::max<std::uint64_t>(1, capacity / (std::uint64_t{line_bytes} * ways));
  if ((sets_ & (sets_ - 1)) == 0) set_mask_ = sets_ - 1;  // the usual case: no division per access
  way_.assign(sets_ * ways_, Way{});
}

std::uint64_t* Cache::access(std::uint64_t line, bool& hit) {
  ++clock_;
  Way* set = &way_[(set_mask_ != kNoMask ? line & set_mask_ : line % sets_) * ways_];
  for (std::uint32_t w = 0; w < ways_; ++w)
    if (set[w].tag == line) {
      hit = true;
      if (replacement_ == CacheReplacement::lru) set[w].stamp = clock_;
      return &set[w].ready;
    }
  hit = false;
  return allocate(set, line);
}

std::uint64_t* Cache::allocate(Way* set, std::uint64_t line) {
  // The victim: an empty way first (lowest), else by the policy.
  Way* victim = nullptr;
  for (std::uint32_t w = 0; w < ways_ && !victim; ++w)
    if (set[w].tag == ~std::uint64_t{0}) victim = &set[w];
  if (!victim) {
    if (replacement_ == CacheReplacement::random) {
      rng_ ^= rng_ << 13;  // xorshift64: the same sequence on every run
      rng_ ^= rng_ >> 7;
      rng_ ^= rng_ << 17;
      victim = &set[rng_ % ways_];
    } else {  // lru: least recently used; fifo: filled first
      victim = set;
      for (std::uint32_t w = 1; w < ways_; ++w)
        if (set[w].stamp < victim->stamp) victim = &set[w];
    }
  }
  victim->tag = line;
  victim->stamp = clock_;
  victim->ready = 0;
  return &victim->ready;
}

void Cache::invalidate(std::uint64_t first, std::uint64_t end) {
  for (Way& w : way_)
    if (w.tag >= first && w.tag < end) w.tag = ~std::uint64_t{0};
}

std::uint64_t MissWindow::slot(std::uint64_t t) {
  while (head_ < arrivals_.size() && arrivals_[head_] <= t) pop();
  if (head_ > 64) {  // keep the vector short: drop what has arrived
    arrivals_.erase(arrivals_.begin(), arrivals_.begin() + static_cast<std::ptrdiff_t>(head_));
    head_ = 0;
  }
  if (arrivals_.size() - head_ < limit_) return t;
  const std::uint64_t free = arrivals_[head_];
  pop();
  return std::max(t, free);
}

}  // namespace oprt::timing
