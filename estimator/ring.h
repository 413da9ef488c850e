#pragma once
// A double-ended queue over one growing vector whose slots are reused: the estimator's history
// of snapshots (kilobytes each, one per IMU sample) is pushed at the back and dropped at the
// front at IMU rate, and a std::deque of such elements allocates and frees one node per push.
// Here a push reuses the slot dropped earlier (its contents are stale: the caller overwrites
// them); the storage only grows, doubling, when the ring is full.
// Invariants: size_ <= slots_.size(); element i lives at slots_[(head_ + i) % slots_.size()].

#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

namespace kestrel::estimator {

template <typename T>
class Ring {
 public:
  bool empty() const { return size_ == 0; }
  size_t size() const { return size_; }
  T& operator[](size_t i) { return slots_[slot(i)]; }
  const T& operator[](size_t i) const { return slots_[slot(i)]; }
  T& front() { return (*this)[0]; }
  const T& front() const { return (*this)[0]; }
  T& back() { return (*this)[size_ - 1]; }
  const T& back() const { return (*this)[size_ - 1]; }

  /// Appends a slot and returns it, holding whatever it held before (or a default T).
  T& push_back() {
    if (size_ == slots_.size()) grow();
    ++size_;
    return back();
  }
  void pop_front() {
    head_ = slot(1);
    --size_;
  }
  void pop_back() { --size_; }
  void clear() { head_ = size_ = 0; }

  /// Index of the first element for which pred is false (pred partitions the ring).
  template <typename Pred>
  size_t partition_point(Pred pred) const {
    size_t lo = 0, hi = size_;
    while (lo < hi) {
      const size_t mid = lo + (hi - lo) / 2;
      if (pred((*this)[mid])) lo = mid + 1; else hi = mid;
    }
    return lo;
  }

 private:
  size_t slot(size_t i) const {
    const size_t k = head_ + i;
    return k < slots_.size() ? k : k - slots_.size();
  }
  void grow() {
    std::vector<T> bigger(std::max<size_t>(16, 2 * slots_.size()));
    for (size_t i = 0; i < size_; ++i) bigger[i] = std::move((*this)[i]);
    slots_.swap(bigger);
    head_ = 0;
  }

  std::vector<T> slots_;
  size_t head_ = 0, size_ = 0;
};

}  // namespace kestrel::estimator
