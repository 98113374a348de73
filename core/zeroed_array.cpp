#include "core/zeroed_array.h"

#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <new>

namespace femto {

namespace {
constexpr size_t kHugePage = size_t{2} << 20;
}  // namespace

#ifdef FEMTO_SANITIZED_BUILD
// The sanitizer's own allocation: an index past either end is reported, not a silent write into
// the rest of a 2 MiB page.
bool zeroed_arrays_in_pages() {
  return false;
}

void* map_zeroed(size_t bytes) {
  void* p = std::calloc(bytes, 1);
  if (!p) throw std::bad_alloc();
  return p;
}

void unmap_zeroed(void* p, size_t) {
  std::free(p);
}
#else
namespace {
// From half a huge page on, whole 2 MiB pages (the rest of the last one unused): each page
// fault maps 2 MiB instead of 4 KiB.
constexpr size_t kHugeFrom = kHugePage / 2;

size_t mapped_bytes(size_t bytes) {
  return bytes < kHugeFrom ? bytes : (bytes + kHugePage - 1) & ~(kHugePage - 1);
}
}  // namespace

bool zeroed_arrays_in_pages() {
  return true;
}

void* map_zeroed(size_t bytes) {
  if (bytes < kHugeFrom) {
    void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    return p;
  }
  // Map 2 MiB more, keep the aligned part, give back the slack on both sides.
  const size_t used = mapped_bytes(bytes), span = used + kHugePage;
  void* raw = mmap(nullptr, span, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const uintptr_t start = reinterpret_cast<uintptr_t>(raw);
  const uintptr_t aligned = (start + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t stop = start + span, used_end = aligned + used;
  if (aligned > start) munmap(raw, aligned - start);
  if (stop > used_end) munmap(reinterpret_cast<void*>(used_end), stop - used_end);
  void* p = reinterpret_cast<void*>(aligned);
  advise_huge_pages(p, used);
  return p;
}

void unmap_zeroed(void* p, size_t bytes) {
  munmap(p, mapped_bytes(bytes));
}
#endif

void advise_huge_pages(void* p, size_t bytes) {
#ifdef MADV_HUGEPAGE
  const uintptr_t start = reinterpret_cast<uintptr_t>(p);
  const uintptr_t lo = (start + kHugePage - 1) & ~(kHugePage - 1);
  const uintptr_t hi = (start + bytes) & ~(kHugePage - 1);
  if (hi > lo) madvise(reinterpret_cast<void*>(lo), hi - lo, MADV_HUGEPAGE);  // a hint
#else
  (void)p, (void)bytes;
#endif
}

}  // namespace femto
