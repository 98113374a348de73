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
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/distributed/bytes.h"
#include "core/distributed/comm.h"
#include "core/transport/tracker.h"

namespace femto {

namespace chunked_detail {
/// Appends every chunk's list I to all's list I, in chunk order.
template <class Lists, size_t... I>
void concat(std::vector<Lists>& per_chunk, Lists& all, std::index_sequence<I...>) {
  auto one = [&](auto& list, auto index) {
    size_t total = 0;
    for (const Lists& c : per_chunk) total += std::get<decltype(index)::value>(c).size();
    list.reserve(total);
    for (const Lists& c : per_chunk) {
      const auto& part = std::get<decltype(index)::value>(c);
      list.insert(list.end(), part.begin(), part.end());
    }
  };
  (one(std::get<I>(all), std::integral_constant<size_t, I>{}), ...);
}
}  // namespace chunked_detail

/// Calls trace(i, outs..., stats) for every path i in [0, count), `chunk` paths per task; `outs`
/// are the chunk's std::vector<Ts>... (one list per kind of record), left in `per_chunk` (one
/// tuple per chunk, in path order), which the caller keeps across calls so that the lists'
/// memory is reused. Counters are summed into `stats` (across ranks: this rank's chunks).
template <class... Ts, class Trace>
void trace_in_chunk_lists(int64_t count, int64_t chunk, PathStats& stats, Trace&& trace,
                          std::vector<std::tuple<std::vector<Ts>...>>& per_chunk,
                          const distributed::Comm* comm = nullptr) {
  const distributed::Comm& job = comm ? *comm : distributed::alone();
  const int64_t chunks = (count + chunk - 1) / chunk;
  per_chunk.resize(static_cast<size_t>(chunks));
  for (auto& lists : per_chunk) std::apply([](auto&... outs) { (outs.clear(), ...); }, lists);
  tbb::enumerable_thread_specific<PathStats> local;
  tbb::parallel_for(tbb::blocked_range<int64_t>(0, chunks, 1),
                    [&](const tbb::blocked_range<int64_t>& r) {
                      PathStats& st = local.local();
                      for (int64_t c = r.begin(); c != r.end(); ++c) {
                        if (!job.owns(c)) continue;
                        const int64_t end = std::min(count, (c + 1) * chunk);
                        std::apply(
                            [&](auto&... outs) {
                              for (int64_t i = c * chunk; i < end; ++i) trace(i, outs..., st);
                            },
                            per_chunk[static_cast<size_t>(c)]);
                      }
                    });
  for (const PathStats& s : local) stats += s;
  if (!job.single()) {
    distributed::ByteWriter mine;
    for (int64_t c = job.rank(); c < chunks; c += job.size())
      std::apply([&](const auto&... outs) { (mine.put_vector(outs), ...); },
                 per_chunk[static_cast<size_t>(c)]);
    job.all_gather(mine.bytes(), [&](int rank, const std::vector<char>& bytes) {
      if (rank == job.rank()) return;
      distributed::ByteReader in(bytes);
      for (int64_t c = rank; c < chunks; c += job.size())
        std::apply(  // a comma fold runs left to right: the order they were put
            [&](auto&... outs) {
              ((outs = in.get_vector<typename std::decay_t<decltype(outs)>::value_type>()), ...);
            },
            per_chunk[static_cast<size_t>(c)]);
    });
  }
}

/// The same, with each kind's lists concatenated in path order.
template <class... Ts, class Trace>
std::tuple<std::vector<Ts>...> trace_in_chunks_multi(int64_t count, int64_t chunk, PathStats& stats,
                                                     Trace&& trace,
                                                     const distributed::Comm* comm = nullptr) {
  using Lists = std::tuple<std::vector<Ts>...>;
  std::vector<Lists> per_chunk;
  trace_in_chunk_lists<Ts...>(count, chunk, stats, trace, per_chunk, comm);
  Lists all;
  chunked_detail::concat(per_chunk, all, std::index_sequence_for<Ts...>{});
  return all;
}

/// One kind of record: calls trace(i, out, stats) with the chunk's std::vector<T>.
template <class T, class Trace>
std::vector<T> trace_in_chunks(int64_t count, int64_t chunk, PathStats& stats, Trace&& trace,
                               const distributed::Comm* comm = nullptr) {
  return std::get<0>(trace_in_chunks_multi<T>(count, chunk, stats, trace, comm));
}

}  // namespace femto
