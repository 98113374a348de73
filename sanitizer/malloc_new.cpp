// Global operator new and delete over malloc and free, linked into every program of the
// sanitizer build (FEMTO_SANITIZE, FEMTO_FUZZ; docs/RELIABILITY.md).
//
// ASan's own operator new aborts the program when an allocation cannot be served (LLVM 14
// ignores allocator_may_return_null for a throwing new). Without ASan the same allocation throws
// std::bad_alloc, which femto turns into bad input: OpenVDB allocates buffers of the sizes a .vdb
// file states (e.g. a block's compressed size), and docs/RELIABILITY.md promises exit code 2 for
// a corrupt size. Over malloc, which ASan still instruments (redzones, use-after-free, leaks) and
// which returns null with ASAN_OPTIONS=allocator_may_return_null=1 (set by the ctests and
// scripts/fuzz.sh), new throws std::bad_alloc as in the product. What is lost is ASan's check
// that new/delete, new[]/delete[] and malloc/free are not mixed.
#include <cstddef>
#include <cstdlib>
#include <new>

namespace {

void* allocate(std::size_t n) {
  void* p = std::malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  return p;
}

void* allocate(std::size_t n, std::align_val_t align) {
  std::size_t a = static_cast<std::size_t>(align);
  if (a < sizeof(void*)) a = sizeof(void*);
  void* p = nullptr;
  if (posix_memalign(&p, a, n ? n : 1) != 0) throw std::bad_alloc();
  return p;
}

template <class... A>
void* allocate_nothrow(A... a) noexcept {
  try {
    return allocate(a...);
  } catch (const std::bad_alloc&) {
    return nullptr;
  }
}

}  // namespace

void* operator new(std::size_t n) { return allocate(n); }
void* operator new[](std::size_t n) { return allocate(n); }
void* operator new(std::size_t n, std::align_val_t a) { return allocate(n, a); }
void* operator new[](std::size_t n, std::align_val_t a) { return allocate(n, a); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return allocate_nothrow(n); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return allocate_nothrow(n); }
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return allocate_nothrow(n, a);
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  return allocate_nothrow(n, a);
}

void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
