#pragma once
// The loop every bench_kernels benchmark shares, in one of two modes.
//
// Timed (the default): each iteration runs `calls` calls of the kernel on every rank at once
// and takes the slowest rank's wall time (section_times): the manual time of the iteration,
// the same on every rank, so Google Benchmark picks the same iteration count everywhere.
// After the loop, and outside the manual time, the STREAM-triad probe runs kProbePasses
// times.  Counters (rank 0, per call of the kernel (per unit of work: one SOR sweep), per
// rank); all of them information, none gated:
//   min_us, median_us   fastest and median iteration, wall time (Google Benchmark's own
//                       column is the mean, which one preempted iteration drags)
//   cpu_min_us          least CPU time of an iteration (kernel_clock.hpp)
//   bytes_per_cell, flops_per_cell, weno_flops_per_cell   the kernel's counted traffic and
//                       work (kernel_costs.hpp), and the part of the work in WENO5 terms
//   GBps, GFLOPs        counted bytes and flops of one rank / median time (1e9 per second)
//   triad_us, triad_GBps  the probe's fastest pass and one rank's triad bandwidth
//   roofline_fraction   GBps / triad_GBps (above 1 for kernels whose data stay in cache)
//   compute_GFLOPs, compute_fraction   the multiply-add peak (compute_probe.hpp), GFLOPs / it
//   weno_GFLOPs         the WENO5 advection's own roof (compute_probe.hpp)
//   roof_fraction       the kernel's own roof time / its median time: the roof time is the
//                       larger of bytes / triad bandwidth and the compute time, the WENO5
//                       flops at weno_GFLOPs and the rest at compute_GFLOPs
//
// Counted (EFSI_COUNT=1 in the environment, under callgrind; the CI gate,
// ci/microbench_gate.sh): one warm-up of `calls` calls with instrumentation on, then the
// same calls with callgrind's collection on and MPI's own calls left out
// (kernels/grid/mpi_interpose.hpp), dumped under the benchmark's name (callgrind_region.hpp); no clock is
// read.  Counters, per unit of work, the most over ranks: mpi_messages, mpi_bytes (point to
// point, to other ranks), mpi_collectives, mpi_collective_bytes; and units (calls x units
// per call), by which the gate divides callgrind's totals.  Register counted benchmarks with
// one iteration and one repetition (counted_benchmark()).
#include <benchmark/benchmark.h>
#include <mpi.h>

#include <string>
#include <vector>

#include "callgrind_region.hpp"
#include "kernel_clock.hpp"
#include "mpi_interpose.hpp"  // kernels/grid: the census and the hook around MPI calls

namespace efsi::bench {

inline constexpr int kProbePasses = 5;

// Counted cost of one call on one rank.
struct KernelCost {
  double cells = 1;           // owned cells per rank the call works on
  double bytes_per_cell = 0;  // bytes one unit must move, per cell
  double flops_per_cell = 0;  // flops one unit does, per cell
  double weno_flops_per_cell = 0;  // the part of them in WENO5 advection terms (compute_probe.hpp)
  int units = 1;              // units of work per call (sweeps for SOR): figures are per unit
};

// EFSI_COUNT=1 in the environment (read once).
bool count_mode();

// Instrumentation on at the first counted kernel and never off again: callgrind cannot follow
// calls and returns while it is off, so switching it off inside a call (the benchmark's
// frames) leaves returns it never saw entered, with negative costs in the next dumps.
void start_counting_once();

// The benchmark being run: the name its callgrind dump carries (Google Benchmark 1.7 does
// not tell a benchmark its own name; the registration sets it).
void set_kernel_name(const std::string& name);
const std::string& kernel_name();

// Sets the timed counters from the per-call times of the iterations.
void report_kernel(benchmark::State& state, std::vector<Times>& times, const KernelCost& cost);

// Sets the counted counters from this rank's census of the measured calls.
void report_counts(benchmark::State& state, const MpiCensus& used, const KernelCost& cost, int calls);

template <class Body>
void count_kernel(benchmark::State& state, const KernelCost& cost, int calls, Body&& body) {
  const auto run = [&] {
    for (int c = 0; c < calls; ++c) body();
  };
  start_counting_once();
  run();
  MPI_Barrier(MPI_COMM_WORLD);
  const MpiCensus before = mpi_census();
  set_mpi_call_hook(callgrind_toggle_collect);  // MPI calls stay out of the counts
  callgrind_toggle_collect();
  run();
  callgrind_toggle_collect();
  set_mpi_call_hook(nullptr);
  const MpiCensus used = mpi_census() - before;
  callgrind_dump(kernel_name());
  for (auto _ : state) state.SetIterationTime(1.0);
  report_counts(state, used, cost, calls);
}

template <class Body>
void time_kernel(benchmark::State& state, const KernelCost& cost, int calls, Body&& body) {
  if (count_mode()) {
    count_kernel(state, cost, calls, body);
    return;
  }
  std::vector<Times> times;
  for (auto _ : state) {
    const Times t = section_times(MPI_COMM_WORLD, [&] {
      for (int c = 0; c < calls; ++c) body();
    });
    state.SetIterationTime(t.wall);
    const double per = static_cast<double>(calls) * cost.units;
    times.push_back({t.wall / per, t.cpu / per});
  }
  report_kernel(state, times, cost);
}

}  // namespace efsi::bench
