#pragma once
// Wall time of a section on the slowest rank (the reported time) and the CPU time of the
// rank that used least (CLOCK_PROCESS_CPUTIME_ID: all threads of the rank).  A preempted rank
// loses wall time but not CPU time, so on a shared machine the CPU time says how much of a
// slow sample was the kernel's own.  Both are information: the CI gate decides on counted
// work (callgrind_region.hpp), never on a time.
#include <mpi.h>

#include <algorithm>
#include <ctime>
#include <limits>

namespace efsi::bench {

struct Times {
  double wall = 0;  // seconds, the slowest rank's
  double cpu = 0;   // seconds, the CPU time of the rank that used least
};

inline double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// Collective: every rank gets the same two figures.
template <class Body>
Times section_times(MPI_Comm comm, Body&& body) {
  MPI_Barrier(comm);
  const double w0 = MPI_Wtime(), c0 = cpu_seconds();
  body();
  const double local[2] = {MPI_Wtime() - w0, -(cpu_seconds() - c0)};
  double most[2] = {0, 0};
  MPI_Allreduce(local, most, 2, MPI_DOUBLE, MPI_MAX, comm);
  return {most[0], -most[1]};
}

// The least wall and the least CPU time of `passes` calls of run() (each returning Times):
// a probe's times with the least disturbance.
template <class Run>
Times best_of(int passes, Run&& run) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Times t{inf, inf};
  for (int p = 0; p < passes; ++p) {
    const Times r = run();
    t.wall = std::min(t.wall, r.wall);
    t.cpu = std::min(t.cpu, r.cpu);
  }
  return t;
}

}  // namespace efsi::bench
