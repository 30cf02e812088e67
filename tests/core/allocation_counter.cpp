// allocation_counter.cpp: see allocation_counter.hpp.
#include "allocation_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

#if defined(__SANITIZE_ADDRESS__)
#define PUNCTURE_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define PUNCTURE_ASAN 1
#endif
#endif

namespace {
std::atomic<bool> counting{false};
thread_local bool thread_counting = false;
std::atomic<long> allocations{0};
inline bool counts() { return thread_counting || counting.load(std::memory_order_relaxed); }
}  // namespace

#ifdef PUNCTURE_ASAN
// The sanitizer runtime's hook (sanitizer/allocator_interface.h, which GCC
// does not install; libasan exports the function).
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*malloc_hook)(const volatile void*, std::size_t),
                                                         void (*free_hook)(const volatile void*));

namespace {
void on_malloc(const volatile void*, std::size_t) {
  if (counts()) ++allocations;
}
void on_free(const volatile void*) {}
const bool hooks_installed = [] {
  __sanitizer_install_malloc_and_free_hooks(on_malloc, on_free);
  return true;
}();
}  // namespace

namespace puncture::test {
bool allocation_count_from_sanitizer() { return hooks_installed; }
}  // namespace puncture::test

#else

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);

void* malloc(std::size_t n) {
  if (counts()) ++allocations;
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t m) {
  if (counts()) ++allocations;
  return __libc_calloc(n, m);
}
void* realloc(void* p, std::size_t n) {
  if (counts()) ++allocations;
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
}

// operator new goes to __libc_malloc directly, so an allocation by new is
// counted once.
void* operator new(std::size_t n) {
  if (counts()) ++allocations;
  if (void* p = __libc_malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return operator new(n); }
void operator delete(void* p) noexcept { __libc_free(p); }
void operator delete[](void* p) noexcept { __libc_free(p); }
void operator delete(void* p, std::size_t) noexcept { __libc_free(p); }
void operator delete[](void* p, std::size_t) noexcept { __libc_free(p); }

namespace puncture::test {
bool allocation_count_from_sanitizer() { return false; }
}  // namespace puncture::test

#endif

namespace puncture::test {

void start_counting_allocations() {
  allocations = 0;
  counting = true;
}

long stop_counting_allocations() {
  counting = false;
  return allocations.load();
}

void count_this_threads_allocations(bool on) { thread_counting = on; }
void reset_allocation_count() { allocations = 0; }
long allocation_count() { return allocations.load(); }

}  // namespace puncture::test
