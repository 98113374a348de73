#pragma once
// Large arrays of sums that start at zero (the tissue tallies' per-thread fluence and face sums):
// memory straight from the kernel, which is zero already and mapped on first touch, in 2 MiB
// pages where the kernel grants them (Linux transparent huge pages, `madvise` mode). On virtual
// machines a 4 KiB page fault can cost 10-20 us: 86 MiB of sums zeroed by std::vector then take
// about 0.4 s of faults, against 43 faults in 2 MiB pages (docs/PERFORMANCE.md, "Page faults").
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

namespace femto {

/// `bytes` of zeros, in whole 2 MiB-aligned pages from 1 MiB on; nothing is touched. Throws
/// std::bad_alloc.
void* map_zeroed(size_t bytes);
void unmap_zeroed(void* p, size_t bytes);
/// False in sanitizer builds: there the arrays come from calloc, whose bounds the sanitizer checks.
bool zeroed_arrays_in_pages();
/// Asks for 2 MiB pages in the whole 2 MiB-aligned part of [p, p + bytes) that is not touched
/// yet (e.g. a std::vector's buffer after reserve()): a hint, harmless if not granted.
void advise_huge_pages(void* p, size_t bytes);

/// v.resize(n) for a large empty v, with 2 MiB pages asked for before resize() touches them.
template <class T>
void resize_in_huge_pages(std::vector<T>& v, size_t n) {
  if (v.capacity() < n) {
    v.reserve(n);
    advise_huge_pages(v.data(), n * sizeof(T));
  }
  v.resize(n);
}

/// n values of T, all zero at construction; T must be trivial (integers, floating point).
template <class T>
class ZeroedArray {
 public:
  ZeroedArray() = default;
  explicit ZeroedArray(size_t n) : n_(n) {
    if (n > 0) p_ = static_cast<T*>(map_zeroed(n * sizeof(T)));
  }
  ~ZeroedArray() {
    if (p_) unmap_zeroed(p_, n_ * sizeof(T));
  }
  ZeroedArray(ZeroedArray&& o) noexcept
      : p_(std::exchange(o.p_, nullptr)), n_(std::exchange(o.n_, 0)) {}
  ZeroedArray& operator=(ZeroedArray&& o) noexcept {
    std::swap(p_, o.p_);
    std::swap(n_, o.n_);
    return *this;
  }
  ZeroedArray(const ZeroedArray&) = delete;
  ZeroedArray& operator=(const ZeroedArray&) = delete;

  T* data() { return p_; }
  const T* data() const { return p_; }
  size_t size() const { return n_; }
  T& operator[](size_t i) { return p_[i]; }
  const T& operator[](size_t i) const { return p_[i]; }
  T* begin() { return p_; }
  T* end() { return p_ + n_; }
  const T* begin() const { return p_; }
  const T* end() const { return p_ + n_; }

 private:
  T* p_ = nullptr;
  size_t n_ = 0;
};

}  // namespace femto
