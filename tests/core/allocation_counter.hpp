// allocation_counter.hpp: counts heap allocations of this process while
// counting is on (test_no_allocation, the soak), or only those of the threads
// that turned counting on (the haptic loop, while a builder thread allocates
// the next model). Shared by the test_core, test_model, test_realtime and soak
// executables (allocation_counter.cpp must be linked into each).
//
// Without AddressSanitizer: global operator new/new[] are replaced by
// counting versions, and malloc/calloc/realloc are interposed (Eigen
// allocates with malloc, not new), forwarding to glibc's __libc_* functions.
// Under AddressSanitizer the allocator belongs to ASan and must not be
// interposed: the count comes from ASan's own allocation hook
// (__sanitizer_install_malloc_and_free_hooks), which sees every malloc,
// calloc, realloc and operator new. Either way every allocation is counted.
#pragma once

namespace puncture::test {

void start_counting_allocations();
/// Stops counting; returns the number of allocations since start.
long stop_counting_allocations();
/// True when the count comes from the AddressSanitizer hook.
bool allocation_count_from_sanitizer();

/// Thread mode: while the calling thread has it on, its allocations are
/// counted (other threads' are not). The count accumulates over on/off
/// until reset.
void count_this_threads_allocations(bool on);
void reset_allocation_count();
long allocation_count();

}  // namespace puncture::test
