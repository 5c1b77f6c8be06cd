#pragma once
// Google Benchmark under MPI: every rank runs the same benchmark with manual timing; the
// time of an iteration is the maximum over ranks, so every rank sees the same time and
// Google Benchmark picks the same iteration count everywhere.  Only rank 0 reports.
#include <benchmark/benchmark.h>
#include <mpi.h>

#include <functional>

namespace efsi::bench {

// Times `body` on every rank and returns the slowest rank's time.
template <class Body>
double max_over_ranks(MPI_Comm comm, Body&& body) {
  MPI_Barrier(comm);
  const double t0 = MPI_Wtime();
  body();
  double t = MPI_Wtime() - t0, tmax = 0;
  MPI_Allreduce(&t, &tmax, 1, MPI_DOUBLE, MPI_MAX, comm);
  return tmax;
}

// Replaces BENCHMARK_MAIN(): MPI start-up, quiet reporters on ranks other than 0.
// before_finalize (optional) runs after the last benchmark and before MPI_Finalize: it
// releases set-ups a benchmark file keeps between benchmarks (communicators, MPI buffers).
int run_main(int argc, char** argv, const std::function<void()>& before_finalize = {});

}  // namespace efsi::bench
