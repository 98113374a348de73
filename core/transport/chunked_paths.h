#pragma once
// Light paths traced in parallel in fixed chunks, their records gathered in path order: the list
// is the same for any thread count (each path has its own random stream; a chunk's records stay
// together, and chunks are concatenated in order). Across MPI ranks (core/distributed/comm.h),
// chunk c is traced by rank c % ranks and every rank receives the whole list.
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/distributed/bytes.h"
#include "core/distributed/comm.h"
#include "core/transport/tracker.h"

namespace femto {

/// Calls trace(i, out, stats) for every path i in [0, count), `chunk` paths per task; `out` is the
/// chunk's std::vector<T>. Counters are summed into `stats` (across ranks: this rank's chunks).
template <class T, class Trace>
std::vector<T> trace_in_chunks(int64_t count, int64_t chunk, PathStats& stats, Trace&& trace,
                               const distributed::Comm* comm = nullptr) {
  const distributed::Comm& job = comm ? *comm : distributed::alone();
  const int64_t chunks = (count + chunk - 1) / chunk;
  std::vector<std::vector<T>> per_chunk(static_cast<size_t>(chunks));
  tbb::enumerable_thread_specific<PathStats> local;
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, chunks, 1),
                    [&](const tbb::blocked_range<int64_t>& r) {
                      PathStats& st = local.local();
                      for (int64_t c = r.begin(); c != r.end(); ++c) {
                        if (!job.owns(c)) continue;
                        std::vector<T>& out = per_chunk[static_cast<size_t>(c)];
                        const int64_t end = std::min(count, (c + 1) * chunk);
                        for (int64_t i = c * chunk; i < end; ++i) trace(i, out, st);
                      }
                    });
  for (const PathStats& s : local) stats += s;
  if (!job.single()) {
    distributed::ByteWriter mine;
    for (int64_t c = job.rank(); c < chunks; c += job.size())
      mine.put_vector(per_chunk[static_cast<size_t>(c)]);
    job.all_gather(mine.bytes(), [&](int rank, const std::vector<char>& bytes) {
      if (rank == job.rank()) return;
      distributed::ByteReader in(bytes);
      for (int64_t c = rank; c < chunks; c += job.size())
        per_chunk[static_cast<size_t>(c)] = in.get_vector<T>();
    });
  }
  size_t total = 0;
  for (const auto& v : per_chunk) total += v.size();
  std::vector<T> all;
  all.reserve(total);
  for (const auto& v : per_chunk) all.insert(all.end(), v.begin(), v.end());
  return all;
}

}  // namespace femto
