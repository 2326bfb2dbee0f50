// Where `algray` hands a run to algray-full, the same command line linked with the web server and Open MPI.
#pragma once

#include <ostream>

namespace algray::cli {

// Whether an MPI launcher (mpirun, mpiexec, srun with PMI or PMIx) started this process, read from the variables
// launchers set. A process started alone never initialises MPI, so it starts as fast as before.
bool started_by_mpi_launcher();

// Replaces this process with algray-full, with the same arguments, environment and standard streams. It is
// looked for beside this executable (a build tree) and in its install's libexec/algray. Returns only when that
// fails, after saying why on `err`: the exit code.
int hand_off_to_full(char** argv, std::ostream& err);

}  // namespace algray::cli
