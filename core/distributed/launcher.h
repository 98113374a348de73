#pragma once
// What the environment says about an MPI launcher (mpirun, mpiexec, srun): read by both builds,
// so that a build without MPI refuses to run as N independent copies.

namespace femto::distributed {

/// The job size an MPI launcher announced (OMPI_COMM_WORLD_SIZE, PMI_SIZE), 1 when there is
/// none; 0 when a launcher is present but did not say (PMIX_RANK only).
int launcher_size();

}  // namespace femto::distributed
