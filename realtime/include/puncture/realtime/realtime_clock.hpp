// realtime_clock.hpp: the monotonic clock, deadline waits and thread set-up
// of the haptic loop.
//
// wait_until_s(deadline, margin): sleeps (clock_nanosleep, absolute
// CLOCK_MONOTONIC) until `margin` before the deadline, then spins on the clock
// until the deadline: the sleep frees the core for other threads, the spin
// absorbs the kernel's wake-up latency (tens of microseconds on a shared VM).
// make_thread_realtime(priority, cpu): SCHED_FIFO at `priority` (if the
// process may), optional pinning to `cpu`, 1 ns timer slack; returns a
// sentence saying what was obtained (or refused, and why).
#pragma once

#include <string>

namespace puncture::realtime {

double monotonic_now_s() noexcept;
void sleep_until_s(double t_s) noexcept;
void wait_until_s(double deadline_s, double spin_margin_s) noexcept;
std::string make_thread_realtime(int priority, int cpu);

}  // namespace puncture::realtime
