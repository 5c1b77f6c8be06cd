#pragma once
// Wall time of a section on the slowest rank (the reported time), and two CPU times for the
// CI gate's figure, which must not move when other jobs share the cores:
//   cpu   the CPU time of the rank that used least (CLOCK_PROCESS_CPUTIME_ID: all threads of
//         the rank, so with t OpenMP threads t times the wall time of a parallel section).
//         A preempted rank loses wall time but not CPU time, and its peer, waiting for its
//         messages, spins in MPI and does count that time, so the rank with the least CPU
//         time is the one that waited least.  The figure for kernels whose work is
//         communication (halo exchange, global reduction).
//   work  the CPU time less the CPU time inside MPI's blocking calls (mpi_wait_clock.hpp),
//         slowest rank: the rank's own work, whoever was preempted when.  The figure for
//         every other kernel: a step waits hundreds of times, and when every core runs
//         another job as well, each wait lasts until the peer is scheduled again.
#include <mpi.h>

#include <ctime>

#include "mpi_wait_clock.hpp"

namespace efsi::bench {

struct Times {
  double wall = 0;  // seconds, the slowest rank's
  double cpu = 0;   // seconds, the CPU time of the rank that used least
  double work = 0;  // seconds, CPU time outside MPI's blocking calls, the slowest rank's
};

inline double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Collective: every rank gets the same three figures.
template <class Body>
Times section_times(MPI_Comm comm, Body&& body) {
  MPI_Barrier(comm);
  const double w0 = MPI_Wtime(), c0 = cpu_seconds(), m0 = mpi_wait_cpu_seconds();
  body();
  const double cpu = cpu_seconds() - c0, wait = mpi_wait_cpu_seconds() - m0;
  const double local[3] = {MPI_Wtime() - w0, -cpu, cpu - wait};
  double most[3] = {0, 0, 0};
  MPI_Allreduce(local, most, 3, MPI_DOUBLE, MPI_MAX, comm);
  return {most[0], -most[1], most[2]};
}

}  // namespace efsi::bench
