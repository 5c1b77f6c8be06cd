// One explicit ACM step of the FSI solver on the paper's weak-scaling block: 64^3 cells of
// 3.6^3 per rank, ranks side by side in x (global cells {64 P, 64, 64}, box {3.6 P, 3.6,
// 3.6}), the two body-centred lattice particles of each rank's 3.6^3 lattice cell, G = 50,
// dt = 1.25e-5, sync and async halo modes. Built the way every driver builds a run:
// ChannelCase -> validate_case -> CartDecomposition -> build_solver.
//
//   OMP_NUM_THREADS=1 mpirun -n 2 --bind-to core build/bin/bench_acm_step
//     --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// One warm-up step (first touch of the work arrays, MPI connections, async exchange in
// flight) is taken outside the timing, then the solver's RegionTimers are reset. Each
// iteration is one step, timed on every rank, the slowest rank's time reported.
//
// Counters (rank 0):
//   MLUPS            million cell updates per second of the GLOBAL grid, from the manual time
//   compute_ms       per step: stencil kernels (stress, v*, transport, divergence, ACM, projection)
//   halo_pack_ms, halo_unpack_ms, halo_mpi_ms (posting and waiting), reduce_ms (ACM moments +
//                    blow-up check): per step, this rank's RegionTimers
//   other_ms         step time minus the regions above (untimed code, timer skew, the slowest
//                    rank's lag over rank 0)
//   global_cells, particles, ranks: the set-up, for reference
#include <mpi.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "channel_case.hpp"
#include "decomposition.hpp"
#include "fsi_solver.hpp"
#include "mpi_benchmark.hpp"
#include "particles.hpp"
#include "region_timers.hpp"

namespace {

using namespace efsi;

constexpr int kBlock = 64;         // cells per rank per axis
constexpr double kBlockLen = 3.6;  // length per rank per axis (one lattice cell: 2 particles)
constexpr double kDt = 1.25e-5;
constexpr double kG = 50.0;
constexpr int kSteps = 20;         // timed steps per repetition (each ~0.1 s on one core)

struct Setup {
  ChannelCase c;
  std::vector<Particle> particles;
  std::unique_ptr<CartDecomposition> dec;
  std::unique_ptr<FsiSolver> solver;

  explicit Setup(CommMode mode) {
    int p = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &p);
    c.domain.cells = {kBlock * p, kBlock, kBlock};
    c.domain.length = {kBlockLen * p, kBlockLen, kBlockLen};
    c.solver.dt = kDt;
    c.solver.physics.G = kG;
    c.solver.comm = mode;
    c.method = PressureKind::acm;
    // Every lattice site of the box: 2 per 3.6^3 lattice cell, i.e. 2 per rank.
    c.particles = static_cast<int>(lattice_site_count(c.domain, c.particle));
    c.forced_dims = {p, 1, 1};
    // t_end only bounds the a-priori velocity for the time-step check: a generous run length.
    particles = validate_case(c, p, 1000 * kDt);
    dec = std::make_unique<CartDecomposition>(MPI_COMM_WORLD, c.domain.cells, kTransportHalo, c.forced_dims);
    solver = build_solver(c, *dec, particles);
  }
};

void BM_AcmStep(benchmark::State& state, CommMode mode) {
  Setup s(mode);
  FsiSolver& solver = *s.solver;
  solver.step();  // warm-up, outside the timers
  solver.timers().reset();

  double total = 0.0;
  for (auto _ : state) {
    const double t = bench::max_over_ranks(MPI_COMM_WORLD, [&] { solver.step(); });
    state.SetIterationTime(t);
    total += t;
  }
  const RegionTimers timers = solver.timers();  // before the last exchange completes
  solver.complete_exchange();                   // nothing in flight when the solver goes

  const double steps = static_cast<double>(state.iterations());
  const double cells = static_cast<double>(product(s.c.domain.cells));
  const double per_ms = 1e3 / steps;
  double regions = 0.0;
  for (Region r : {Region::compute, Region::halo_pack, Region::halo_unpack, Region::halo_mpi, Region::reduce})
    regions += timers.get(r);
  state.counters["MLUPS"] = total > 0 ? cells * steps / total / 1e6 : 0.0;
  state.counters["compute_ms"] = timers.get(Region::compute) * per_ms;
  state.counters["halo_pack_ms"] = timers.get(Region::halo_pack) * per_ms;
  state.counters["halo_unpack_ms"] = timers.get(Region::halo_unpack) * per_ms;
  state.counters["halo_mpi_ms"] = timers.get(Region::halo_mpi) * per_ms;
  state.counters["reduce_ms"] = timers.get(Region::reduce) * per_ms;
  state.counters["other_ms"] = (total - regions) * per_ms;
  state.counters["global_cells"] = cells;
  state.counters["particles"] = static_cast<double>(s.particles.size());
  state.counters["ranks"] = static_cast<double>(s.dec->size());
}

BENCHMARK_CAPTURE(BM_AcmStep, sync, CommMode::sync)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(kSteps);
BENCHMARK_CAPTURE(BM_AcmStep, async, CommMode::async)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(kSteps);

}  // namespace

int main(int argc, char** argv) { return efsi::bench::run_main(argc, argv); }
