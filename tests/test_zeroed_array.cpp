// ZeroedArray (core/zeroed_array.h): zeros from the kernel for the tissue tallies' sums. Catches
// memory that is not zero, a mapping that is too short or misplaced by the alignment (a write at
// either end would fault or land outside), and moves that lose or double-free the mapping.
#include <catch2/catch.hpp>

#include <cstdint>
#include <numeric>
#include <vector>

#include "core/zeroed_array.h"

using namespace femto;

TEST_CASE("zeroed arrays start at zero, hold every index and move", "[zeroed_array]") {
  // Small (4 KiB pages) and large (2 MiB-aligned, the size not a multiple of a page).
  for (const size_t n : {size_t{1}, size_t{1000}, size_t{200'000}, size_t{3'000'001}}) {
    ZeroedArray<uint64_t> a(n);
    REQUIRE(a.size() == n);
    REQUIRE(a.data() != nullptr);
    CHECK(std::accumulate(a.begin(), a.end(), uint64_t{0}) == 0);
    if (zeroed_arrays_in_pages() && n * sizeof(uint64_t) >= (size_t{1} << 20))
      CHECK(reinterpret_cast<uintptr_t>(a.data()) % (size_t{2} << 20) == 0);
    a[0] = 7;
    a[n - 1] += 5;
    ZeroedArray<uint64_t> b(std::move(a));
    CHECK(a.size() == 0);
    CHECK(a.data() == nullptr);
    const uint64_t first = n > 1 ? 7 : 12, last = n > 1 ? 5 : 12;  // n = 1: both on one value
    CHECK(b[0] == first);
    CHECK(b[n - 1] == last);
    ZeroedArray<uint64_t> c;
    c = std::move(b);
    CHECK(c.size() == n);
    CHECK(c[0] == first);
    CHECK(c[n - 1] == last);
  }
  ZeroedArray<double> empty(0);
  CHECK(empty.size() == 0);
  CHECK(empty.begin() == empty.end());
}

TEST_CASE("a vector resized in huge pages holds zeros", "[zeroed_array]") {
  std::vector<float> v;
  resize_in_huge_pages(v, 5'000'000);
  REQUIRE(v.size() == 5'000'000);
  CHECK(std::accumulate(v.begin(), v.end(), 0.0) == 0.0);
  v.back() = 1.0f;
  resize_in_huge_pages(v, 10);  // shrinking keeps the values
  CHECK(v.size() == 10);
}
