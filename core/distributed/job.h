#pragma once
// Start and end of a distributed job. Built with FEMTO_MPI and started by mpirun (or srun),
// the process joins MPI_COMM_WORLD; otherwise it is a job of one and nothing here does anything.
#include <string>

namespace femto::distributed {

/// Whether this build can run under mpirun (FEMTO_MPI).
bool mpi_built();
/// Whether the environment says an MPI launcher started this process.
bool launched_by_mpi();
/// Joins the job when launched_by_mpi(); call once, before the job's threads start work.
void start(int& argc, char**& argv);
/// Leaves the job after a successful command (waits for every rank).
void finish();
/// Ends the whole job with `code` (MPI_Abort) after this rank failed; a job of one just exits.
[[noreturn]] void abort_job(int code);
/// "rank 1 of 4" under MPI, "" for a job of one (for messages).
std::string rank_label();

}  // namespace femto::distributed
