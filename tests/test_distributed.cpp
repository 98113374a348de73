// Tests of the pieces of core/distributed/ that run without mpirun: the byte buffers partial
// results travel in, and the job of one process. The multi-rank runs are ctests (mpi_*, in
// tests/mpi/compare_ranks.sh).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

#include "core/distributed/bytes.h"
#include "core/distributed/comm.h"

using namespace femto::distributed;

namespace {
uint64_t bits(double x) {
  uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}
}  // namespace

// Catches: a buffer that converts values (loses -0.0, NaN payloads or subnormals), so rank 0
// would fold different bits than a single process.
TEST_CASE("distributed: bytes round-trip bit for bit", "[distributed]") {
  const std::vector<double> v = {-0.0, 1.0 / 3.0, std::numeric_limits<double>::denorm_min(),
                                 std::nan("0x5a5a"), -std::numeric_limits<double>::infinity()};
  ByteWriter w;
  w.put<int>(7);
  w.put_vector(v);
  w.put_array(v.data() + 1, 2);
  ByteReader r(w.bytes());
  CHECK(r.get<int>() == 7);
  const std::vector<double> back = r.get_vector<double>();
  REQUIRE(back.size() == v.size());
  for (size_t i = 0; i < v.size(); ++i) CHECK(bits(back[i]) == bits(v[i]));
  double two[2];
  r.get_array(two, 2);
  CHECK(bits(two[0]) == bits(v[1]));
  CHECK(bits(two[1]) == bits(v[2]));
  CHECK(r.done());
}

// Catches: a truncated message from a rank read past its end instead of failing.
TEST_CASE("distributed: a short message is an error", "[distributed]") {
  ByteWriter w;
  w.put<uint64_t>(1000);  // announces 1000 doubles, holds none
  ByteReader r(w.bytes());
  CHECK_THROWS(r.get_vector<double>());
}

// Catches: a process started without mpirun that skips work units or folds nothing.
TEST_CASE("distributed: a job of one does everything itself", "[distributed]") {
  const Comm& one = world();  // the tests never run under mpirun
  CHECK(one.single());
  CHECK(one.root());
  for (int64_t u = 0; u < 100; ++u) CHECK(one.owns(u));
  std::vector<char> seen;
  one.gather({'a', 'b'}, [&](int rank, const std::vector<char>& bytes) {
    CHECK(rank == 0);
    seen = bytes;
  });
  CHECK(seen == std::vector<char>{'a', 'b'});
  std::vector<uint64_t> sums = {1, 2, 3};
  one.sum_to_root(sums);
  CHECK(sums == std::vector<uint64_t>{1, 2, 3});
  CHECK(one.from_root(42) == 42);
}
