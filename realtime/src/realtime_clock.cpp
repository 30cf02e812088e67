#include "puncture/realtime/realtime_clock.hpp"

#include <pthread.h>
#include <sched.h>
#include <sys/prctl.h>
#include <time.h>

#include <cerrno>
#include <cmath>
#include <cstring>

namespace puncture::realtime {

double monotonic_now_s() noexcept {
  timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void sleep_until_s(double t_s) noexcept {
  if (!(t_s > 0.0)) return;
  timespec ts;
  double whole = 0.0;
  const double frac = std::modf(t_s, &whole);
  ts.tv_sec = static_cast<time_t>(whole);
  ts.tv_nsec = static_cast<long>(frac * 1e9);
  if (ts.tv_nsec >= 1000000000L) ts.tv_nsec = 999999999L;
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
}

void wait_until_s(double deadline_s, double spin_margin_s) noexcept {
  if (monotonic_now_s() < deadline_s - spin_margin_s) sleep_until_s(deadline_s - spin_margin_s);
  while (monotonic_now_s() < deadline_s) {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
}

std::string make_thread_realtime(int priority, int cpu) {
  std::string what;
  prctl(PR_SET_TIMERSLACK, 1UL, 0, 0, 0);
  if (priority > 0) {
    sched_param param{};
    param.sched_priority = priority;
    const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &param);
    what = rc == 0 ? "SCHED_FIFO priority " + std::to_string(priority)
                   : std::string("normal scheduling (SCHED_FIFO refused: ") + std::strerror(rc) + ")";
  } else {
    what = "normal scheduling (real-time priority not requested)";
  }
  if (cpu >= 0) {
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    const int rc = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
    what += rc == 0 ? ", pinned to CPU " + std::to_string(cpu)
                    : ", not pinned (CPU " + std::to_string(cpu) + ": " + std::strerror(rc) + ")";
  }
  return what + ", timer slack 1 ns";
}

}  // namespace puncture::realtime
