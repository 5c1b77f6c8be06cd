#include "first_failure.hpp"

#include <algorithm>
#include <vector>

namespace efsi {

std::string first_failure(MPI_Comm comm, const std::string& failure) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int mine = failure.empty() ? size : rank;
  int first = size;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size) return {};
  int length = rank == first ? static_cast<int>(failure.size()) : 0;
  MPI_Bcast(&length, 1, MPI_INT, first, comm);
  std::vector<char> text(static_cast<std::size_t>(length) + 1, '\0');
  if (rank == first) std::copy(failure.begin(), failure.end(), text.begin());
  MPI_Bcast(text.data(), length, MPI_CHAR, first, comm);
  return std::string(text.data(), static_cast<std::size_t>(length));
}

}  // namespace efsi
