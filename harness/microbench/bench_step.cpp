// One whole solver step of each method on the paper's weak-scaling block: 64^3 cells of
// 3.6^3 per rank, ranks side by side in x (global cells {64 P, 64, 64}, box {3.6 P, 3.6,
// 3.6}), the two body-centred lattice particles of each rank's 3.6^3 lattice cell, G = 50.
// Built the way every driver builds a run: ChannelCase -> validate_case ->
// CartDecomposition -> build_solver.
//
//   BM_Step/acm/{sync,async}             dt 1.25e-5, explicit stress (the paper's ACM)
//   BM_Step/sor_ns213_nc20/{sync,async}  dt 6.25e-5, N_S = 213 SOR sweeps per step (eps 1e-3),
//                                        Crank-Nicolson stress by N_C = 20 sweeps
//   BM_Step/fft/sync                     dt 6.25e-5, exact FFT pressure, explicit stress
//
//   OMP_NUM_THREADS=1 build/bin/bench_step --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//   OMP_NUM_THREADS=1 mpirun -n 2 --bind-to core build/bin/bench_step --benchmark_repetitions=5 ...
//   (one method: --benchmark_filter='BM_Step/acm/')
//
// One warm-up step (first touch of the work arrays, FFTW and MPI set-up, async exchange in
// flight) is taken outside the timing, then the solver's RegionTimers are reset. Each
// iteration runs a few steps (2 for SOR, about 1 s per step on one core; 5 for the others),
// timed together on every rank; the manual time is the slowest rank's time divided by the
// steps, so the reported time is per step. Google Benchmark's --benchmark_min_time counts
// that per-step time: the wall time of a run is about steps per iteration times longer.
//
// Counters (rank 0; per step, ms, from this rank's RegionTimers):
//   compute_ms       stencil kernels (stress and its Crank-Nicolson sweeps, v*, transport,
//                    divergence, ACM, projection)
//   halo_pack_ms, halo_unpack_ms, halo_mpi_ms (blocking exchanges; async posting and
//                    progress), halo_wait_ms (the async final wait), reduce_ms (moments,
//                    blow-up check), sor_sweeps_ms (SOR colour updates), fft_solve_ms (FFTs,
//                    Thomas, reordering), transpose_mpi_ms (the FFT solve's MPI_Alltoallv)
//   other_ms         step time minus all the regions above (untimed code, timer skew, the
//                    slowest rank's lag over rank 0)
//   MLUPS            million cell updates per second of the GLOBAL grid, from the manual time
//   global_cells, particles, ranks, steps_per_iteration, nc and the method's resolved settings
//                    (SOR: ns, eps): the set-up, for reference
#include <mpi.h>

#include <string>

#include "channel_setup.hpp"
#include "mpi_benchmark.hpp"
#include "region_timers.hpp"

namespace {

using namespace efsi;
using bench::StepCase;

constexpr int kBlock = 64;  // cells per rank per axis

void BM_Step(benchmark::State& state, const StepCase& m) {
  bench::ChannelSetup s(m, kBlock);
  FsiSolver& solver = *s.solver;
  solver.step();  // warm-up, outside the timers
  solver.timers().reset();

  double total = 0.0;
  for (auto _ : state) {
    const double t = bench::max_over_ranks(MPI_COMM_WORLD, [&] {
      for (int n = 0; n < m.steps_per_iter; ++n) solver.step();
    });
    state.SetIterationTime(t / m.steps_per_iter);
    total += t;
  }
  const RegionTimers timers = solver.timers();  // before the last exchange completes
  solver.complete_exchange();                   // nothing in flight when the solver goes

  const double steps = static_cast<double>(state.iterations()) * m.steps_per_iter;
  const double cells = static_cast<double>(product(s.c.domain.cells));
  const double per_ms = 1e3 / steps;
  double regions = 0.0;
  for (int r = 0; r < region_count(); ++r) {
    const Region region{r};
    regions += timers.get(region);
    state.counters[std::string(to_string(region)) + "_ms"] = timers.get(region) * per_ms;
  }
  state.counters["other_ms"] = (total - regions) * per_ms;
  state.counters["MLUPS"] = total > 0 ? cells * steps / total / 1e6 : 0.0;
  state.counters["global_cells"] = cells;
  state.counters["particles"] = static_cast<double>(s.particles.size());
  state.counters["ranks"] = static_cast<double>(s.dec->size());
  state.counters["steps_per_iteration"] = m.steps_per_iter;
  for (const auto& [key, value] : m.choice.values) state.counters[key] = value;  // ns, eps
  state.counters["nc"] = m.choice.cn_sweeps;
}

// Registered before main() runs, like the BENCHMARK macros, under names built from the cases.
[[maybe_unused]] const bool kRegistered = [] {
  for (const StepCase& m : bench::step_cases())
    benchmark::RegisterBenchmark(("BM_Step/" + bench::step_case_name(m)).c_str(), BM_Step, m)
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond);
  return true;
}();

}  // namespace

int main(int argc, char** argv) { return efsi::bench::run_main(argc, argv); }
