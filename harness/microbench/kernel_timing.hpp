#pragma once
// The timing loop and the roofline counters every bench_kernels benchmark shares.
//
// Each iteration runs `calls` calls of the kernel on every rank at once and takes the
// slowest rank's wall time (section_times): the manual time of the iteration, the same on
// every rank, so Google Benchmark picks the same iteration count everywhere (Google Benchmark's
// own time column is per iteration; the counters below are per call).  After the loop, and
// outside the manual time, the STREAM-triad probes (memory, then cache-resident) run
// kProbePasses times each.
//
// Counters (rank 0, per call of the kernel (per unit of work: one SOR sweep), per rank):
//   min_us, median_us   fastest and median iteration, wall time (the time Google Benchmark
//                       reports is the mean, which one preempted iteration on a shared machine
//                       drags)
//   cpu_min_us          least CPU time of an iteration (kernel_clock.hpp: the rank that used
//                       least)
//   work_min_us         least CPU time outside MPI's blocking calls of an iteration
//                       (kernel_clock.hpp: the slowest rank's); with EFSI_MPI_WAIT_CLOCK
//                       unset, no call is counted and this is the CPU time of the slowest
//                       rank (mpi_wait_clock.hpp)
//   gate_us             the gate's figure: work_min_us, or cpu_min_us for a communication
//                       kernel (KernelCost::communication)
//   bytes_per_cell, flops_per_cell   the kernel's counted traffic and work (see the comment
//                       beside each kernel), per owned cell of one rank
//   GBps, GFLOPs        counted bytes and flops of one rank / median time (1e9 per second)
//   triad_us, triad_cpu_us, triad_GBps  the probe's fastest pass (wall time; least CPU
//                       time) and one rank's triad bandwidth from the wall time
//   roofline_fraction   GBps / triad_GBps: the share of the measured memory bandwidth the
//                       kernel reaches (above 1 for kernels whose data stay in cache)
//   cache_triad_us, cache_triad_cpu_us, cache_triad_GBps  the same for the cache-resident
//                       triad (stream_probe.hpp), run after the memory one
//   ratio               gate_us / cache_triad_cpu_us: the kernel's time in units of the
//                       cache-resident probe's, machine-independent to first order; the CI
//                       gate compares it (gate.py takes the probe's least CPU time over the
//                       whole run); the global reduction replaces it by gate_us over an MPI
//                       latency probe (bench_kernels.cpp, set_comm_probe)
#include <benchmark/benchmark.h>
#include <mpi.h>

#include <vector>

#include "kernel_clock.hpp"
#include "mpi_wait_clock.hpp"

namespace efsi::bench {

inline constexpr int kProbePasses = 5;

// Counted cost of one call on one rank.
struct KernelCost {
  double cells = 1;           // owned cells per rank the call works on
  double bytes_per_cell = 0;  // bytes one unit must move, per cell
  double flops_per_cell = 0;  // flops one unit does, per cell
  int units = 1;              // units of work per call (sweeps for SOR): times are per unit
  bool communication = false; // the work is communication: the gate uses the CPU time, not
                              // the work (kernel_clock.hpp)
};

// Sets the counters above from the per-call times of the iterations.
void report_kernel(benchmark::State& state, std::vector<Times>& times, const KernelCost& cost);

template <class Body>
void time_kernel(benchmark::State& state, const KernelCost& cost, int calls, Body&& body) {
  std::vector<Times> times;
  set_mpi_wait_clock(mpi_wait_clock_requested() && !cost.communication);
  for (auto _ : state) {
    const Times t = section_times(MPI_COMM_WORLD, [&] {
      for (int c = 0; c < calls; ++c) body();
    });
    state.SetIterationTime(t.wall);
    const double per = static_cast<double>(calls) * cost.units;
    times.push_back({t.wall / per, t.cpu / per, t.work / per});
  }
  set_mpi_wait_clock(false);
  report_kernel(state, times, cost);
}

}  // namespace efsi::bench
