// spsc_ring.hpp: a bounded single-producer single-consumer ring of trivially
// copyable records, lock-free and allocation-free after construction.
//
// The haptic thread produces (tick samples for the view's graph, records for
// the session recorder); another thread consumes. try_push never waits: when
// the ring is full it returns false and the producer counts the loss.
//   In:  capacity (rounded up to a power of two, >= 2), allocated once.
//   Out: try_push (producer only), try_pop (consumer only).
// Memory order: the producer publishes a slot with a release store of head,
// the consumer frees it with a release store of tail (classic Lamport queue).
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <type_traits>
#include <vector>

namespace puncture::realtime {

template <class T>
class SpscRing {
  static_assert(std::is_trivially_copyable_v<T>, "SpscRing holds trivially copyable records");

 public:
  explicit SpscRing(std::size_t capacity) {
    std::size_t n = 2;
    while (n < capacity) n <<= 1;
    slots_.resize(n);  // value-initialised: the pages are touched here, not in the haptic path
    mask_ = n - 1;
  }
  SpscRing(const SpscRing&) = delete;
  SpscRing& operator=(const SpscRing&) = delete;

  std::size_t capacity() const { return slots_.size(); }

  /// Producer: copies `value` in; false (and nothing written) when full.
  bool try_push(const T& value) noexcept {
    const std::uint64_t head = head_.load(std::memory_order_relaxed);
    if (head - tail_cache_ >= slots_.size()) {
      tail_cache_ = tail_.load(std::memory_order_acquire);
      if (head - tail_cache_ >= slots_.size()) return false;
    }
    slots_[head & mask_] = value;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  /// Consumer: copies the oldest record out; false when empty.
  bool try_pop(T& out) noexcept {
    const std::uint64_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_cache_) {
      head_cache_ = head_.load(std::memory_order_acquire);
      if (tail == head_cache_) return false;
    }
    out = slots_[tail & mask_];
    tail_.store(tail + 1, std::memory_order_release);
    return true;
  }

  /// Records waiting (exact when called by either side while the other is idle).
  std::size_t size() const {
    return static_cast<std::size_t>(head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire));
  }

 private:
  std::vector<T> slots_;
  std::size_t mask_ = 1;
  alignas(64) std::atomic<std::uint64_t> head_{0};  ///< written by the producer
  std::uint64_t tail_cache_ = 0;                    ///< producer's last view of tail
  alignas(64) std::atomic<std::uint64_t> tail_{0};  ///< written by the consumer
  std::uint64_t head_cache_ = 0;                    ///< consumer's last view of head
};

}  // namespace puncture::realtime
