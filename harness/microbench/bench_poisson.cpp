// The pressure Poisson solvers of the SMAC methods on n^3 cells per rank, ranks side by
// side in x (global cells {n P, n, n}, box 3.6 per 64 cells along every axis, so the spacing
// is the paper's 3.6/64 at every n), rhs a fixed pseudo-random field with zero global mean:
//
//   BM_FftSolve/n        one exact FFT solve (FftPoisson, FFTW_MEASURE plans), n = 64, 128
//   BM_SorSweep/mode/... one four-colour SOR sweep (SorPoisson), n = 64, sync and async
//   BM_MgSolve/n/eps/solver  one multigrid solve (MgPoisson) to a relative residual of
//                        1e-eps: solver 0 PFMG (the method's; n = 64, 128, eps = 3, 4),
//                        1 SMG and 2 CG preconditioned by a PFMG V-cycle (n = 64), for the
//                        choice of solver
//   BM_SorSolve/n/eps    SOR sweeps from x = 0 to the same relative residual 1e-eps (n = 64,
//                        128, eps = 3, 4): the count the SOR method would need on this rhs
//
//   OMP_NUM_THREADS=1 build/bin/bench_poisson --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//   OMP_NUM_THREADS=1 mpirun -n 2 --bind-to core build/bin/bench_poisson --benchmark_repetitions=5 ...
//
// Every timed section runs on every rank; the slowest rank's time is the one used, and
// rank 0 reports.  The set-up (plans, fields, a warm-up solve or sweep, MPI connections) is
// outside the timing; the RegionTimers are reset after the warm-up.
//
// BM_FftSolve: each iteration times one solve(rhs, x, factor) (the manual time), then, on
// every rank and outside the manual time, two references of the same local size:
//   - one forward + backward pair of plain FFTW 3D transforms of one rank's n^3 block
//     (fftw_plan_dft_r2c_3d / c2r_3d, out of place, FFTW_MEASURE, the solver's thread count);
//   - one pass copying rhs's owned cells into x (one read and one write of the field).
// Counters (rank 0; per solve):
//   fft_ms, transpose_ms  the solve's RegionTimers: kFftSolveRegion (FFTs, Thomas,
//                         reordering) and kTransposeRegion (its MPI_Alltoallv)
//   fftw_3d_ms, copy_ms   the two references, slowest rank, mean over the iterations
//   ratio_to_fftw_3d      solve time / fftw_3d_ms: how close the solve comes to the cost of
//                         its FFTs alone (a forward and a backward 3D transform is the least
//                         an FFT solve must do; 1 = no overhead from the pencil transposes,
//                         the Thomas sweeps and the reordering)
//   ratio_to_copy         solve time / copy_ms: the solve's cost in passes over the field's
//                         memory, each pass one read and one write of n^3 doubles (a field is
//                         2 MiB at 64^3, 16 MiB at 128^3: the pass runs largely from L3 cache)
//   mpi_bytes             bytes this rank sends through MPI_Alltoallv per solve
//   global_cells, ranks   the set-up, for reference
//
// BM_MgSolve: each iteration times one solve(rhs, x, factor, {1e-eps}) from x = 0.
// Counters (rank 0; per solve): cycles (V-cycles), residual (the relative residual reached),
// mg_solve_ms and mg_mpi_ms (the RegionTimers: work, and the time inside MPI by PMPI
// interposition), setup_ms (hypre's grid, matrix and PFMG set-up, once), global_cells, ranks.
//
// BM_SorSolve: the warm-up counts the sweeps N that bring the RMS residual to 1e-eps of its
// initial value (one sweep at a time); each iteration then times x = 0 and one call of
// sweeps(rhs, N), as the SOR method runs its N_S per step.  Counters (rank 0): sweeps,
// residual (reached), ms_per_sweep, global_cells, ranks.
//
// BM_SorSweep: each iteration runs 10 sweeps, either as 10 calls of sweeps(rhs, 1)
// (sweeps_per_call:1) or as one call of sweeps(rhs, 10) (sweeps_per_call:10, the way the SOR
// pressure method calls it with N_S sweeps); the manual time is the iteration's time / 10.
// Every call first brings x's ghosts up to date, so sweeps_per_call:1 does 5 exchanges per
// sweep and sweeps_per_call:10 4.1.
// Counters (rank 0; per sweep, ms): sor_sweeps_ms (colour updates), halo_mpi_ms (blocking
// exchanges; posting and progress in async), halo_wait_ms (the async final wait),
// halo_pack_ms, halo_unpack_ms from the solver's RegionTimers; other_ms = sweep time minus
// those five (untimed code, the slowest rank's lag over rank 0); global_cells, ranks.
#include <fftw3.h>
#include <mpi.h>

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "decomposition.hpp"
#include "domain.hpp"
#include "fft_poisson.hpp"
#include "field.hpp"
#include "fsi_state.hpp"
#include "mg_poisson.hpp"
#include "mpi_benchmark.hpp"
#include "region_timers.hpp"
#include "runtime.hpp"
#include "sor_poisson.hpp"

namespace {

using namespace efsi;

constexpr double kLenPer64 = 3.6;  // box length per 64 cells, every axis
constexpr int kSorSweeps = 10;     // sweeps per iteration of BM_SorSweep

// Deterministic value in [-1, 1) from a global cell index.
double noise(int gi, int gj, int gk) {
  std::uint64_t z = 0x9E3779B97F4A7C15ull + (std::uint64_t(gi) << 42) + (std::uint64_t(gj) << 21) + std::uint64_t(gk);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  z ^= z >> 31;
  return static_cast<double>(z >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

// n^3 cells per rank, ranks along x; x and rhs cell-centred, rhs random with zero mean.
struct Problem {
  Domain domain;
  std::unique_ptr<CartDecomposition> dec;
  std::unique_ptr<Field> x, rhs;

  explicit Problem(int n) {
    int p = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &p);
    const double len = kLenPer64 * n / 64.0;
    domain = Domain{{n * p, n, n}, {len * p, len, len}};
    dec = std::make_unique<CartDecomposition>(MPI_COMM_WORLD, domain.cells, kTransportHalo, Int3{p, 1, 1});
    x = std::make_unique<Field>(*dec, FieldSpec{"x", Stagger::cell, 1, WallParity::even});
    rhs = std::make_unique<Field>(*dec, FieldSpec{"rhs", Stagger::cell, 1, WallParity::even});
    x->fill(0.0);
    rhs->fill(0.0);
    const Int3& m = rhs->n();
    const Int3& o = rhs->offset();
    double sum = 0.0;
    for (int k = 0; k < m[Z]; ++k)
      for (int j = 0; j < m[Y]; ++j)
        for (int i = 0; i < m[X]; ++i) sum += (*rhs)(i, j, k) = noise(o[X] + i, o[Y] + j, o[Z] + k);
    MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, dec->comm());
    const double mean = sum / static_cast<double>(product(domain.cells));
    for (int k = 0; k < m[Z]; ++k)
      for (int j = 0; j < m[Y]; ++j)
        for (int i = 0; i < m[X]; ++i) (*rhs)(i, j, k) -= mean;
  }
};

// A forward r2c and a backward c2r 3D transform of one rank's block, plain FFTW.
class Fftw3dPair {
 public:
  explicit Fftw3dPair(const Int3& n) : real_(fftw_alloc_real(static_cast<std::size_t>(product(n)))) {
    const std::size_t nc = static_cast<std::size_t>(n[Z]) * n[Y] * (n[X] / 2 + 1);
    complex_ = fftw_alloc_complex(nc);
    // FftPoisson's constructor has called fftw_init_threads(); plan with the same threads.
    fftw_plan_with_nthreads(max_threads());
    // Row-major with x fastest, as in a Field.  Planning with FFTW_MEASURE overwrites the
    // arrays, so they are filled afterwards.
    fwd_ = fftw_plan_dft_r2c_3d(n[Z], n[Y], n[X], real_, complex_, FFTW_MEASURE);
    bwd_ = fftw_plan_dft_c2r_3d(n[Z], n[Y], n[X], complex_, real_, FFTW_MEASURE);
    for (std::int64_t q = 0; q < product(n); ++q) real_[q] = noise(static_cast<int>(q), 1, 2);
  }
  ~Fftw3dPair() {
    fftw_destroy_plan(fwd_);
    fftw_destroy_plan(bwd_);
    fftw_free(complex_);
    fftw_free(real_);
  }
  Fftw3dPair(const Fftw3dPair&) = delete;
  Fftw3dPair& operator=(const Fftw3dPair&) = delete;

  // The unnormalised round trip scales the data by the cell count; that changes no timing
  // (no overflow or denormals over the benchmark's few thousand passes at 64^3 or more).
  void run() {
    fftw_execute(fwd_);
    fftw_execute(bwd_);
  }

 private:
  double* real_;
  fftw_complex* complex_ = nullptr;
  fftw_plan fwd_ = nullptr, bwd_ = nullptr;
};

// One pass over the owned cells: x = rhs.
void copy_owned(const Field& from, Field& to) {
  const Int3& n = from.n();
#pragma omp parallel for collapse(2) schedule(static)
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j) {
      const double* src = from.data() + from.index(0, j, k);
      double* dst = &to(0, j, k);
      for (int i = 0; i < n[X]; ++i) dst[i] = src[i];
    }
  benchmark::ClobberMemory();
}

void BM_FftSolve(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  Problem pb(n);
  RegionTimers timers;
  FftPoisson fft(*pb.dec, pb.domain, FftPoisson::Planning::measure, &timers);
  Fftw3dPair ref(pb.dec->local());
  const double factor = 1.0 / 6.25e-5;  // 1/dt, as in the SMAC step (free: folded into the division)

  fft.solve(*pb.rhs, *pb.x, factor);  // warm-up, outside the timers
  ref.run();
  copy_owned(*pb.rhs, *pb.x);
  timers.reset();

  double t_solve = 0.0, t_fftw = 0.0, t_copy = 0.0;
  for (auto _ : state) {
    const double t = bench::max_over_ranks(MPI_COMM_WORLD, [&] { fft.solve(*pb.rhs, *pb.x, factor); });
    state.SetIterationTime(t);
    t_solve += t;
    t_fftw += bench::max_over_ranks(MPI_COMM_WORLD, [&] { ref.run(); });
    t_copy += bench::max_over_ranks(MPI_COMM_WORLD, [&] { copy_owned(*pb.rhs, *pb.x); });
  }

  const double iters = static_cast<double>(state.iterations());
  const double per_ms = 1e3 / iters;
  state.counters["fft_ms"] = timers.get(kFftSolveRegion) * per_ms;
  state.counters["transpose_ms"] = timers.get(kTransposeRegion) * per_ms;
  state.counters["fftw_3d_ms"] = t_fftw * per_ms;
  state.counters["copy_ms"] = t_copy * per_ms;
  state.counters["ratio_to_fftw_3d"] = t_fftw > 0 ? t_solve / t_fftw : 0.0;
  state.counters["ratio_to_copy"] = t_copy > 0 ? t_solve / t_copy : 0.0;
  state.counters["mpi_bytes"] = static_cast<double>(fft.doubles_sent()) * sizeof(double);
  state.counters["global_cells"] = static_cast<double>(product(pb.domain.cells));
  state.counters["ranks"] = static_cast<double>(pb.dec->size());
}

void BM_SorSweep(benchmark::State& state, CommMode mode) {
  const int per_call = static_cast<int>(state.range(0));
  Problem pb(64);
  RegionTimers timers;
  SorPoisson sor(*pb.dec, pb.domain, *pb.x, mode, &timers);
  sor.sweeps(*pb.rhs, 1);  // warm-up, outside the timers
  timers.reset();

  double total = 0.0;
  for (auto _ : state) {
    const double t = bench::max_over_ranks(MPI_COMM_WORLD, [&] {
      for (int done = 0; done < kSorSweeps; done += per_call) sor.sweeps(*pb.rhs, per_call);
    });
    state.SetIterationTime(t / kSorSweeps);
    total += t;
  }

  const double per_ms = 1e3 / (static_cast<double>(state.iterations()) * kSorSweeps);
  state.counters["sor_sweeps_ms"] = timers.get(kSorSweepsRegion) * per_ms;
  state.counters["halo_mpi_ms"] = timers.get(Region::halo_mpi) * per_ms;
  state.counters["halo_wait_ms"] = timers.get(Region::halo_wait) * per_ms;
  state.counters["halo_pack_ms"] = timers.get(Region::halo_pack) * per_ms;
  state.counters["halo_unpack_ms"] = timers.get(Region::halo_unpack) * per_ms;
  double regions = 0.0;
  for (Region r : {kSorSweepsRegion, Region::halo_mpi, Region::halo_wait, Region::halo_pack, Region::halo_unpack})
    regions += timers.get(r);
  state.counters["other_ms"] = (total - regions) * per_ms;
  state.counters["global_cells"] = static_cast<double>(product(pb.domain.cells));
  state.counters["ranks"] = static_cast<double>(pb.dec->size());
}

void BM_MgSolve(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const MgStop stop{std::pow(10.0, -static_cast<double>(state.range(1))), 1000};
  const MgSolver kind = static_cast<MgSolver>(state.range(2));
  Problem pb(n);
  RegionTimers timers;
  MgPoisson mg(*pb.dec, pb.domain, &timers, kind);
  state.SetLabel(to_string(kind));
  const double factor = 1.0 / 6.25e-5;
  MgResult r = mg.solve(*pb.rhs, *pb.x, factor, stop);  // warm-up, outside the timers
  timers.reset();
  for (auto _ : state) {
    const double t = bench::max_over_ranks(MPI_COMM_WORLD, [&] { r = mg.solve(*pb.rhs, *pb.x, factor, stop); });
    state.SetIterationTime(t);
  }
  const double per_ms = 1e3 / static_cast<double>(state.iterations());
  state.counters["cycles"] = r.cycles;
  state.counters["residual"] = r.residual;
  state.counters["mg_solve_ms"] = timers.get(kMgSolveRegion) * per_ms;
  state.counters["mg_mpi_ms"] = timers.get(kMgMpiRegion) * per_ms;
  state.counters["setup_ms"] = mg.setup_seconds() * 1e3;
  state.counters["global_cells"] = static_cast<double>(product(pb.domain.cells));
  state.counters["ranks"] = static_cast<double>(pb.dec->size());
}

void BM_SorSolve(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const double eps = std::pow(10.0, -static_cast<double>(state.range(1)));
  Problem pb(n);
  SorPoisson sor(*pb.dec, pb.domain, *pb.x, CommMode::sync);
  const double factor = 1.0 / 6.25e-5;
  const double r0 = sor.residual_rms(*pb.rhs, factor);
  double r = 1.0;
  int sweeps = 0;
  constexpr int kMaxSweeps = 20000;
  while (r > eps && sweeps < kMaxSweeps) {
    sor.sweeps(*pb.rhs, 1, factor);
    r = sor.residual_rms(*pb.rhs, factor) / r0;
    ++sweeps;
  }
  if (r > eps) {
    state.SkipWithError("SOR did not reach the tolerance in 20000 sweeps");
    return;
  }
  double total = 0.0;
  for (auto _ : state) {
    const double t = bench::max_over_ranks(MPI_COMM_WORLD, [&] {
      pb.x->fill(0.0);
      sor.sweeps(*pb.rhs, sweeps, factor);
    });
    state.SetIterationTime(t);
    total += t;
  }
  state.counters["sweeps"] = sweeps;
  state.counters["residual"] = r;
  state.counters["ms_per_sweep"] = 1e3 * total / (static_cast<double>(state.iterations()) * sweeps);
  state.counters["global_cells"] = static_cast<double>(product(pb.domain.cells));
  state.counters["ranks"] = static_cast<double>(pb.dec->size());
}

BENCHMARK(BM_MgSolve)
    ->ArgNames({"n", "eps", "solver"})
    ->ArgsProduct({{64, 128}, {3, 4}, {0}})
    ->ArgsProduct({{64}, {3, 4}, {1, 2}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SorSolve)
    ->ArgNames({"n", "eps"})
    ->ArgsProduct({{64, 128}, {3, 4}})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FftSolve)->ArgName("n")->Arg(64)->Arg(128)->UseManualTime()->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SorSweep, sync, CommMode::sync)
    ->ArgName("sweeps_per_call")
    ->Arg(1)
    ->Arg(kSorSweeps)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_SorSweep, async, CommMode::async)
    ->ArgName("sweeps_per_call")
    ->Arg(1)
    ->Arg(kSorSweeps)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) { return efsi::bench::run_main(argc, argv); }
