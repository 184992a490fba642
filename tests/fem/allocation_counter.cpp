// Replaces the global operator new of the test binary with a counting one.
#include "allocation_counter.h"

#include <SuiteSparse_config.h>

#include <atomic>
#include <cstdlib>
#include <new>

namespace {

std::atomic<bool> counting{false};
std::atomic<std::size_t> news{0};
std::atomic<std::size_t> suitesparse_allocs{0};

void* counted_new(std::size_t size) {
  if (counting.load(std::memory_order_relaxed)) news.fetch_add(1, std::memory_order_relaxed);
  void* p = std::malloc(size == 0 ? 1 : size);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}

void* count_malloc(std::size_t size) {
  if (counting.load(std::memory_order_relaxed))
    suitesparse_allocs.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size);
}
void* count_calloc(std::size_t n, std::size_t size) {
  if (counting.load(std::memory_order_relaxed))
    suitesparse_allocs.fetch_add(1, std::memory_order_relaxed);
  return std::calloc(n, size);
}
void* count_realloc(void* p, std::size_t size) {
  if (counting.load(std::memory_order_relaxed))
    suitesparse_allocs.fetch_add(1, std::memory_order_relaxed);
  return std::realloc(p, size);
}

}  // namespace

void* operator new(std::size_t size) {
  return counted_new(size);
}
void* operator new[](std::size_t size) {
  return counted_new(size);
}
void* operator new(std::size_t size, std::align_val_t align) {
  if (counting.load(std::memory_order_relaxed)) news.fetch_add(1, std::memory_order_relaxed);
  const auto alignment = static_cast<std::size_t>(align);
  void* p = std::aligned_alloc(alignment, (size + alignment - 1) / alignment * alignment);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}
void* operator new[](std::size_t size, std::align_val_t align) {
  return operator new(size, align);
}
void operator delete(void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  std::free(p);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}

namespace fahr::fem::test {

void enable_allocation_counting(bool on) {
  counting.store(on);
}
std::size_t new_count() {
  return news.load();
}
std::size_t suitesparse_alloc_count() {
  return suitesparse_allocs.load();
}
void reset_allocation_counts() {
  news.store(0);
  suitesparse_allocs.store(0);
}
void hook_suitesparse_allocations() {
  SuiteSparse_config.malloc_func = count_malloc;
  SuiteSparse_config.calloc_func = count_calloc;
  SuiteSparse_config.realloc_func = count_realloc;
}

}  // namespace fahr::fem::test
