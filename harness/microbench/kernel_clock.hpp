#pragma once
// Wall and CPU time of a section on every rank, the slowest rank's of each.
//
// The CPU time (CLOCK_PROCESS_CPUTIME_ID: all threads of the rank) is what the CI gate
// compares: on a machine whose cores are shared with other jobs, a rank that is preempted
// loses wall time but not CPU time, so the least CPU time of many iterations stays close to
// the kernel's cost even when no iteration ran undisturbed (a rank that spins in MPI while
// its peer is preempted still counts the spin).
#include <mpi.h>

#include <ctime>

namespace efsi::bench {

struct Times {
  double wall = 0, cpu = 0;  // seconds
};

inline double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

template <class Body>
Times max_times_over_ranks(MPI_Comm comm, Body&& body) {
  MPI_Barrier(comm);
  const double w0 = MPI_Wtime(), c0 = cpu_seconds();
  body();
  const double local[2] = {MPI_Wtime() - w0, cpu_seconds() - c0};
  double slowest[2] = {0, 0};
  MPI_Allreduce(local, slowest, 2, MPI_DOUBLE, MPI_MAX, comm);
  return {slowest[0], slowest[1]};
}

}  // namespace efsi::bench
