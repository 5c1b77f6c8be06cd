#pragma once
// An output that could not be written: no space, no permission, a short write, a failed
// close.  Raised alike on every rank, so that drivers print it as one line and exit with
// status 5 without a hang, and record nothing as valid.
#include <mpi.h>

#include <stdexcept>
#include <string>

namespace efsi {

class OutputError : public std::runtime_error {
 public:
  explicit OutputError(const std::string& what) : std::runtime_error(what) {}
};

// Collective over `comm`: `failure` is this rank's reason, empty when it succeeded.  When
// any rank failed, every rank throws OutputError with the lowest failing rank's reason
// (first_failure.hpp).
void agree_on_failure(MPI_Comm comm, const std::string& failure);

}  // namespace efsi
