#include "output_error.hpp"

#include "first_failure.hpp"

namespace efsi {

void agree_on_failure(MPI_Comm comm, const std::string& failure) {
  const std::string first = first_failure(comm, failure);
  if (!first.empty()) throw OutputError(first);
}

}  // namespace efsi
