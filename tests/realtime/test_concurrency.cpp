// The lock-free exchanges between the haptic thread and the rest: the SPSC
// ring keeps order and loses nothing it accepted; the triple buffer always
// hands the reader a complete, newest-or-newer value.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "puncture/realtime/spsc_ring.hpp"
#include "puncture/realtime/triple_buffer.hpp"

namespace puncture::realtime {
namespace {

TEST(SpscRing, FifoOrderAndFullRingRefuses) {
  SpscRing<int> ring(3);  // rounded up to 4
  EXPECT_EQ(ring.capacity(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(ring.try_push(i));
  EXPECT_FALSE(ring.try_push(99));  // full: refused, nothing overwritten
  int v = -1;
  for (int i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.try_pop(v));
    EXPECT_EQ(v, i);
  }
  EXPECT_FALSE(ring.try_pop(v));
  EXPECT_TRUE(ring.try_push(7));
  ASSERT_TRUE(ring.try_pop(v));
  EXPECT_EQ(v, 7);
}

TEST(SpscRing, TwoThreadsLoseNothingAccepted) {
  struct Item {
    long sequence;
    long check;
  };
  SpscRing<Item> ring(64);
  constexpr long kItems = 300000;
  std::atomic<long> refused{0};
  std::thread producer([&] {
    for (long i = 0; i < kItems;) {
      if (ring.try_push({i, 3 * i + 1}))
        ++i;
      else
        ++refused;
    }
  });
  long expected = 0;
  bool ordered = true;
  Item item{};
  while (expected < kItems) {
    if (!ring.try_pop(item)) continue;
    ordered &= item.sequence == expected && item.check == 3 * expected + 1;
    ++expected;
  }
  producer.join();
  EXPECT_TRUE(ordered);
  EXPECT_EQ(ring.size(), 0u);
}

TEST(TripleBuffer, ReaderSeesCompleteNewerValues) {
  struct Value {
    long a[16];
  };
  TripleBuffer<Value> buffer([](Value& v) {
    for (long& x : v.a) x = -1;
  });
  constexpr long kWrites = 200000;
  std::atomic<bool> done{false};
  std::thread writer([&] {
    for (long i = 0; i < kWrites; ++i) {
      Value& v = buffer.back();
      for (long& x : v.a) x = i;
      buffer.publish();
    }
    done = true;
  });
  long last = -1, updates = 0;
  bool torn = false, backwards = false;
  for (;;) {
    const bool writer_done = done.load();
    if (!buffer.update()) {
      if (writer_done) break;  // nothing new and nothing more to come
      continue;
    }
    const Value& v = buffer.front();
    for (long x : v.a) torn |= x != v.a[0];
    backwards |= v.a[0] < last;
    last = v.a[0];
    ++updates;
  }
  writer.join();
  EXPECT_FALSE(torn);
  EXPECT_FALSE(backwards);
  EXPECT_GT(updates, 0);
  EXPECT_EQ(buffer.front().a[0], kWrites - 1);  // the last value always arrives
}

TEST(TripleBuffer, NoUpdateWithoutPublish) {
  TripleBuffer<int> buffer([](int& v) { v = 0; });
  EXPECT_FALSE(buffer.update());
  buffer.back() = 5;
  EXPECT_FALSE(buffer.update());  // written but not published
  buffer.publish();
  EXPECT_TRUE(buffer.update());
  EXPECT_EQ(buffer.front(), 5);
  EXPECT_FALSE(buffer.update());
}

}  // namespace
}  // namespace puncture::realtime
