#pragma once
// One rank's failure made every rank's: the set-up checks that run on one rank and the writes
// that fail on some raise the same error everywhere, so no rank waits on another.
#include <mpi.h>

#include <string>

namespace efsi {

// Collective over `comm`: `failure` is this rank's reason, empty when it succeeded.  Returns,
// on every rank, the reason of the lowest failing rank ("" when none failed).
std::string first_failure(MPI_Comm comm, const std::string& failure);

}  // namespace efsi
