// triple_buffer.hpp: the latest value from one writer thread to one reader
// thread, wait-free on both sides (no locks, no allocation after construction).
//
// Three buffers: the writer fills its back buffer and publish()es it by
// swapping it with the middle one; the reader's update() swaps its front
// buffer with the middle one if the writer published since. Neither side
// ever waits for the other, and the reader always sees a complete value.
// Used for the view snapshot (haptic thread -> renderer) and for the
// mouse/keyboard target (view thread -> haptic thread).
//   In:  an initialiser applied to all three buffers (so preallocated sizes match).
//   Out: writer: back(), publish(); reader: update(), front().
#pragma once

#include <atomic>
#include <cstdint>

namespace puncture::realtime {

template <class T>
class TripleBuffer {
 public:
  TripleBuffer() = default;
  template <class Init>
  explicit TripleBuffer(Init&& init) {
    for (T& b : buffers_) init(b);
  }
  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;

  // --- writer ---
  T& back() noexcept { return buffers_[back_]; }
  void publish() noexcept {
    const std::uint8_t old = middle_.exchange(static_cast<std::uint8_t>(back_ | kFresh), std::memory_order_acq_rel);
    back_ = old & kIndex;
  }

  // --- reader ---
  /// True if a new value was published since the last update(); front() is then the newest.
  bool update() noexcept {
    if (!(middle_.load(std::memory_order_relaxed) & kFresh)) return false;
    const std::uint8_t old = middle_.exchange(front_, std::memory_order_acq_rel);
    front_ = old & kIndex;
    return true;
  }
  const T& front() const noexcept { return buffers_[front_]; }
  T& front() noexcept { return buffers_[front_]; }

 private:
  static constexpr std::uint8_t kIndex = 0x3;
  static constexpr std::uint8_t kFresh = 0x4;
  T buffers_[3];
  std::uint8_t back_ = 0;   ///< writer's buffer
  std::uint8_t front_ = 1;  ///< reader's buffer
  alignas(64) std::atomic<std::uint8_t> middle_{2};
};

}  // namespace puncture::realtime
