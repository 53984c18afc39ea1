// A queue in one ring of storage that doubles when full and never shrinks: pushing and
// popping allocate nothing once it has grown to the most it held (std::deque allocates and
// frees a block each time its ends cross one, which a FIFO's per-ray traffic does all the
// time). The subset of std::deque's interface the ray FIFOs use.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace oprt::hw {

template <typename T>
class Ring {
 public:
  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  T& front() { return slots_[head_]; }
  const T& front() const { return slots_[head_]; }
  const T& back() const { return slots_[(head_ + size_ - 1) & mask_]; }
  const T& operator[](std::size_t i) const { return slots_[(head_ + i) & mask_]; }
  void pop_front() {
    head_ = (head_ + 1) & mask_;
    --size_;
  }
  template <typename... A>
  void emplace_back(A&&... a) {
    if (size_ == slots_.size()) grow();
    slots_[(head_ + size_++) & mask_] = T{std::forward<A>(a)...};
  }
  void push_back(const T& v) { emplace_back(v); }
  void clear() { head_ = size_ = 0; }

 private:
  void grow() {
    std::vector<T> bigger(slots_.empty() ? 16 : 2 * slots_.size());
    for (std::size_t i = 0; i < size_; ++i) bigger[i] = std::move(slots_[(head_ + i) & mask_]);
    slots_.swap(bigger);
    head_ = 0;
    mask_ = slots_.size() - 1;
  }
  std::vector<T> slots_;
  std::size_t head_ = 0, size_ = 0, mask_ = 0;
};

}  // namespace oprt::hw
