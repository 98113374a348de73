// The job under MPI (FEMTO_MPI): MPI_COMM_WORLD. MPI calls come from one thread at a time
// (MPI_THREAD_SERIALIZED): the command's thread, which oneTBB may run inside a task arena.
#include <mpi.h>

#include <algorithm>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "core/distributed/comm.h"
#include "core/distributed/job.h"
#include "core/distributed/launcher.h"

namespace femto::distributed {

namespace {
constexpr size_t kPiece = size_t{1} << 30;  // bytes per message: MPI counts are int
constexpr int kTag = 7;

class MpiComm final : public Comm {
 public:
  void join(int rank, int size) {
    rank_ = rank;
    size_ = size;
  }

  void gather(const std::vector<char>& mine, const Fold& fold) const override {
    if (size_ <= 1) return fold(0, mine);
    if (!root()) {
      const uint64_t n = mine.size();
      MPI_Send(&n, 1, MPI_UINT64_T, 0, kTag, MPI_COMM_WORLD);
      for (size_t at = 0; at < mine.size(); at += kPiece)
        MPI_Send(mine.data() + at, static_cast<int>(std::min(kPiece, mine.size() - at)), MPI_BYTE,
                 0, kTag, MPI_COMM_WORLD);
      return;
    }
    fold(0, mine);
    std::vector<char> theirs;
    for (int r = 1; r < size_; ++r) {  // rank order: the fold order of a single process
      uint64_t n = 0;
      MPI_Recv(&n, 1, MPI_UINT64_T, r, kTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      theirs.resize(static_cast<size_t>(n));
      for (size_t at = 0; at < theirs.size(); at += kPiece)
        MPI_Recv(theirs.data() + at, static_cast<int>(std::min(kPiece, theirs.size() - at)),
                 MPI_BYTE, r, kTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      fold(r, theirs);
    }
  }

  void all_gather(const std::vector<char>& mine, const Fold& fold) const override {
    if (size_ <= 1) return fold(0, mine);
    std::vector<char> theirs;
    for (int r = 0; r < size_; ++r) {  // rank r broadcasts its bytes, in pieces
      const bool me = r == rank_;
      uint64_t n = me ? mine.size() : 0;
      MPI_Bcast(&n, 1, MPI_UINT64_T, r, MPI_COMM_WORLD);
      if (!me) theirs.resize(static_cast<size_t>(n));
      char* data = me ? const_cast<char*>(mine.data()) : theirs.data();
      for (size_t at = 0; at < n; at += kPiece)
        MPI_Bcast(data + at, static_cast<int>(std::min<size_t>(kPiece, n - at)), MPI_BYTE, r,
                  MPI_COMM_WORLD);
      fold(r, me ? mine : theirs);
    }
  }

  void sum_to_root(std::vector<uint64_t>& values) const override {
    if (size_ <= 1) return;
    constexpr size_t piece = kPiece / sizeof(uint64_t);
    for (size_t at = 0; at < values.size(); at += piece) {
      const int n = static_cast<int>(std::min(piece, values.size() - at));
      if (root())
        MPI_Reduce(MPI_IN_PLACE, values.data() + at, n, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
      else
        MPI_Reduce(values.data() + at, nullptr, n, MPI_UINT64_T, MPI_SUM, 0, MPI_COMM_WORLD);
    }
  }

  uint64_t from_root(uint64_t value) const override {
    if (size_ > 1) MPI_Bcast(&value, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
    return value;
  }
};

MpiComm& the_comm() {
  static MpiComm comm;
  return comm;
}
bool g_joined = false;
}  // namespace

const Comm& world() {
  return the_comm();
}
bool mpi_built() {
  return true;
}
bool launched_by_mpi() {
  return launcher_size() != 1;
}

void start(int& argc, char**& argv) {
  if (!launched_by_mpi() || g_joined) return;
  int provided = 0;
  if (MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS) {
    std::fprintf(stderr, "femto: failure: MPI_Init_thread failed\n");
    std::exit(1);
  }
  if (provided < MPI_THREAD_SERIALIZED) {
    std::fprintf(stderr,
                 "femto: failure: this MPI library does not allow calls from threads "
                 "(MPI_THREAD_SERIALIZED)\n");
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  // Errors in MPI calls end the job (the default handler), with MPI's own message.
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  the_comm().join(rank, size);
  g_joined = true;
}

void finish() {
  if (!g_joined) return;
  MPI_Finalize();
  g_joined = false;
}

void abort_job(int code) {
  std::fflush(stdout);
  std::fflush(stderr);
  if (g_joined && the_comm().size() > 1) MPI_Abort(MPI_COMM_WORLD, code);
  if (g_joined) MPI_Finalize();
  std::exit(code);
}

std::string rank_label() {
  if (the_comm().size() <= 1) return "";
  return "rank " + std::to_string(the_comm().rank()) + " of " + std::to_string(the_comm().size());
}

}  // namespace femto::distributed
