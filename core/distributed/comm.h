#pragma once
// The processes of one job (MPI ranks under mpirun, else a job of one). Work units are dealt out
// by index; partial results travel to rank 0 as bytes and are folded there in rank order, so
// that rank 0 adds sums in the order a single process adds them (docs/mpi.md). Nothing here
// needs MPI: core/distributed/mpi_job.cpp provides the MPI implementation.
#include <cstdint>
#include <functional>
#include <vector>

namespace femto::distributed {

class Comm {
 public:
  virtual ~Comm() = default;
  int rank() const { return rank_; }
  int size() const { return size_; }
  bool root() const { return rank_ == 0; }
  bool single() const { return size_ <= 1; }
  /// Whether this process does work unit `unit` (dealt out round-robin over the ranks).
  bool owns(int64_t unit) const { return size_ <= 1 || unit % size_ == rank_; }

  using Fold = std::function<void(int rank, const std::vector<char>& bytes)>;
  /// Collective. Rank 0 calls fold(r, bytes of rank r) for r = 0, 1, ... in order (its own
  /// `mine` first); the other ranks send `mine` and return.
  virtual void gather(const std::vector<char>& mine, const Fold& fold) const { fold(0, mine); }
  /// Collective. Every rank calls fold(r, bytes of rank r) for r = 0, 1, ... in order.
  virtual void all_gather(const std::vector<char>& mine, const Fold& fold) const { fold(0, mine); }
  /// Collective: rank 0's values become the elementwise sums over all ranks (exact: integers).
  virtual void sum_to_root(std::vector<uint64_t>& values) const { (void)values; }
  /// Collective: rank 0's value, on every rank (sizes, decisions such as stopping early).
  virtual uint64_t from_root(uint64_t value) const { return value; }
  bool root_flag(bool flag) const { return from_root(flag ? 1 : 0) != 0; }

 protected:
  int rank_ = 0, size_ = 1;
};

/// The job this process belongs to (core/distributed/job.h starts it).
const Comm& world();
/// A job of one, for code run without a job (tests, libraries).
inline const Comm& alone() {
  static const Comm one;
  return one;
}

}  // namespace femto::distributed
