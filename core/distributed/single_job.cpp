// A job of one process: the build without FEMTO_MPI.
#include <cstdio>
#include <cstdlib>

#include "core/distributed/comm.h"
#include "core/distributed/job.h"
#include "core/distributed/launcher.h"

namespace femto::distributed {

const Comm& world() {
  static const Comm single;
  return single;
}
bool mpi_built() {
  return false;
}
bool launched_by_mpi() {
  return launcher_size() != 1;
}
void start(int&, char**&) {
  // N copies of a build without MPI would each render everything into the same folder.
  if (launched_by_mpi()) {
    std::fprintf(stderr,
                 "femto: error: started by an MPI launcher, but this femto was built without MPI "
                 "(FEMTO_MPI is OFF: install libopenmpi-dev and rebuild; docs/mpi.md)\n");
    std::exit(2);
  }
}
void finish() {}
void abort_job(int code) {
  std::exit(code);
}
std::string rank_label() {
  return "";
}

}  // namespace femto::distributed
