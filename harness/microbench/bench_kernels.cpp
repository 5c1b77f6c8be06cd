// One Google Benchmark per kernel of the solver, at 32^3 and 64^3 cells per rank, on the
// paper's channel block (channel_setup.hpp: 3.6^3 per rank, ranks side by side in x, two
// particles per rank), with the bytes and flops each kernel must move and do (counted in
// kernel_costs.hpp) and its time relative to a STREAM-triad probe run in the same process
// (stream_probe.hpp; counters in kernel_timing.hpp):
//
//   BM_Stress/n               compute_stress, the six deviatoric stress components
//   BM_MomentumRhs/n          momentum_tendency, the momentum right-hand side dv/dt
//   BM_Transport/n            transport_tendency, WENO5 transport of phi and the six Bt (d/dt)
//   BM_AcmMoments/n           acm_moments: the ACM's local sums and its MPI_Allreduce of 7
//   BM_AcmIncrement/n         AcmPressure::increment: the moments, coefficients and the update
//   BM_SorSweep/{sync,async}/n   one four-colour SOR sweep (time of sweeps(rhs, 10) / 10)
//   BM_FftSolve/n             one FFT Poisson solve (FFTW_MEASURE plans; counted: estimate)
//   BM_HaloExchange/{sync,async}/n  the batched exchange of the eleven state fields (26
//                             neighbours), as each step does it
//   BM_GlobalReduction        the blow-up check's MPI_Allreduce (max of 2 doubles), 100 per
//                             iteration; independent of n, so registered once
//   BM_Step/<method>/<mode>/n one whole step of each method (channel_setup.hpp's cases)
//
//   OMP_NUM_THREADS=1 mpirun -n 2 --bind-to core build/bin/bench_kernels
//       --benchmark_out=results/microbench/bench_kernels-2ranks.json --benchmark_out_format=json
//   (one line; harness/microbench/README.md has the full set of commands)
//
// The kernels run on a state taken a few steps from a laminar Poiseuille flow through the
// particles (ACM, sync): velocities, phi and Bt all vary, as in a run.  Set-ups are built
// once per size and kept between benchmarks and repetitions (one at a time).
#include <mpi.h>

#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "acm.hpp"
#include "acm_work.hpp"
#include "channel_setup.hpp"
#include "fft_poisson.hpp"
#include "fft_work.hpp"
#include "fsi_equations.hpp"
#include "halo_exchange.hpp"
#include "kernel_costs.hpp"
#include "kernel_timing.hpp"
#include "method_registry.hpp"
#include "mg_poisson.hpp"
#include "mpi_benchmark.hpp"
#include "sor_poisson.hpp"
#include "sor_work.hpp"
#include "stream_probe.hpp"

namespace {

using namespace efsi;
using bench::KernelCost;
using efsi::PerCell;
using bench::StepCase;

constexpr int kWarmSteps = 3;  // steps from the laminar flow before the kernels are timed
constexpr int kSorSweeps = 10;  // sweeps per call in BM_SorSweep
constexpr int kReductions = 100;  // MPI_Allreduce calls per iteration in BM_GlobalReduction
const std::vector<int> kSizes{32, 64};

// Halo traffic per exchange and per owned cell of one rank: pack reads the sent points and
// writes the buffer, unpack reads the buffer and writes the ghosts (4 x the bytes sent
// through MPI); a self-copy reads and writes once (2 x the local bytes).  The wall mirrors
// (a few rows) are not counted.  No flops.
double halo_bytes_per_cell(const HaloExchange& h, double cells) {
  return (4.0 * static_cast<double>(h.bytes_sent_mpi()) + 2.0 * static_cast<double>(h.bytes_copied_local())) / cells;
}

// Per-cell halo traffic of the exchanges a step makes, from exchanges built on fields of the
// solver's layouts (the solver's own are private).
struct StepHalos {
  double state = 0, vstar_faces = 0, vstar_full = 0, tau_faces = 0, cell_faces = 0;
};

StepHalos step_halos(const CartDecomposition& dec, const Domain& domain) {
  FsiState st(dec, domain);
  FsiWork w(dec);
  const double cells = static_cast<double>(product(dec.local()));
  auto bytes = [&](std::vector<Field*> f, Reach r) { return halo_bytes_per_cell(HaloExchange(dec, f, r), cells); };
  StepHalos h;
  h.state = bytes(st.all(), Reach::full);
  h.vstar_faces = bytes({&w.vstar[0], &w.vstar[1], &w.vstar[2]}, Reach::faces);
  h.vstar_full = bytes({&w.vstar[0], &w.vstar[1], &w.vstar[2]}, Reach::full);
  h.tau_faces = bytes({&w.tau[0], &w.tau[1], &w.tau[2], &w.tau[3], &w.tau[4], &w.tau[5]}, Reach::faces);
  h.cell_faces = bytes({&w.div}, Reach::faces);
  return h;
}

// The kernels' inputs: an ACM solver's state after kWarmSteps steps, and work arrays of
// our own (D* and dp copied from the solver's last step).
struct KernelSetup {
  int n;
  bench::ChannelSetup ch;
  FsiWork work;
  RegionTimers timers;
  StepHalos halos;

  explicit KernelSetup(int block)
      : n(block), ch(bench::step_cases().front(), block), work(*ch.dec), halos(step_halos(*ch.dec, ch.c.domain)) {
    FsiSolver& solver = *ch.solver;
    solver.impose_laminar_flow();
    for (int s = 0; s < kWarmSteps; ++s) solver.step();
    work.div.copy_from(solver.work().div);
    work.dp.copy_from(solver.work().dp);
    const KernelBoxes full = full_boxes(ch.dec->local());
    compute_stress(state().fields(), physics(), work.root_phi, work.tau, full.stress_centres, full.stress_edges);
  }
  FsiState& state() { return ch.solver->state(); }
  const Physics& physics() const { return ch.c.solver.physics; }
  double dt() const { return ch.c.solver.dt; }
  double cells() const { return static_cast<double>(product(ch.dec->local())); }
  KernelCost cost(PerCell c, double weno_flops = 0) const { return {cells(), c.bytes, c.flops, weno_flops}; }
};

// Counted runs plan FFTs without timing candidates (FftPoisson::Planning::estimate): the
// plan, and so the work, is then the same in every run.
bool timed_planning() { return !bench::count_mode(); }
FftPoisson::Planning fft_planning() {
  return timed_planning() ? FftPoisson::Planning::measure : FftPoisson::Planning::estimate;
}

// One set-up kept at a time: benchmarks of one size run one after another.
std::unique_ptr<KernelSetup> g_kernels;
std::unique_ptr<bench::ChannelSetup> g_step;
std::string g_step_key;

KernelSetup& kernel_setup(int n) {
  if (!g_kernels || g_kernels->n != n) {
    g_kernels.reset();
    g_step.reset();
    g_kernels = std::make_unique<KernelSetup>(n);
  }
  return *g_kernels;
}

// --- the kernels; bytes and flops per cell in kernel_costs.hpp ---------------------------

// kStress: 144 B, 73 flops per cell.
void BM_Stress(benchmark::State& state, int n) {
  KernelSetup& k = kernel_setup(n);
  const KernelBoxes full = full_boxes(k.ch.dec->local());
  bench::time_kernel(state, k.cost(kStress), 1, [&] {
    compute_stress(k.state().fields(), k.physics(), k.work.root_phi, k.work.tau, full.stress_centres, full.stress_edges);
  });
}

// kMomentum: 104 B, 135 flops per cell; the Euler update v* = v + dt dv/dt, as a step writes it.
void BM_MomentumRhs(benchmark::State& state, int n) {
  KernelSetup& k = kernel_setup(n);
  const KernelBoxes full = full_boxes(k.ch.dec->local());
  bench::time_kernel(state, k.cost(kMomentum), 1, [&] {
    momentum_tendency(k.state().fields(), k.physics(), k.work.tau, k.work.vstar, full.momentum,
                      RateOutput::euler_update(k.dt()));
  });
}

// kTransport: 136 B, 1946 flops per cell (1449 of them WENO5 advection); the Euler update of phi and Bt, as a step writes it.
void BM_Transport(benchmark::State& state, int n) {
  KernelSetup& k = kernel_setup(n);
  const KernelBoxes full = full_boxes(k.ch.dec->local());
  bench::time_kernel(state, k.cost(kTransport, kTransportWenoFlops), 1, [&] {
    transport_tendency(k.state().fields(), k.work.phi_new, k.work.B_new, full.transport, 0.0,
                       RateOutput::euler_update(k.dt()));
  });
}

// kAcmMoments: 16 B, 40 flops per cell (+ one MPI_Allreduce of 7 doubles).
void BM_AcmMoments(benchmark::State& state, int n) {
  KernelSetup& k = kernel_setup(n);
  const MPI_Comm comm = k.ch.dec->comm();
  bench::time_kernel(state, k.cost(kAcmMoments), 1, [&] {
    const AcmMoments m = acm_moments(k.work.div, k.state().p(), k.ch.c.domain, comm, k.timers);
    benchmark::DoNotOptimize(m);
  });
}

// kAcmMoments + kAcmUpdate: 40 B, 45 flops per cell (+ the MPI_Allreduce).
void BM_AcmIncrement(benchmark::State& state, int n) {
  KernelSetup& k = kernel_setup(n);
  AcmPressure acm;
  PressureInputs in{k.state(), k.work, k.physics(), k.dt(), k.timers};
  bench::time_kernel(state, k.cost(kAcmMoments + kAcmUpdate), 1, [&] { acm.increment(in); });
}

// sor_sweep_cost (16 B per pass, 14 flops) + the halo exchanges of x: one per pass (4, or 2
// with x whole), plus the one at the start of each call (sweeps(rhs, 10)).
void BM_SorSweep(benchmark::State& state, int n, CommMode mode) {
  KernelSetup& k = kernel_setup(n);
  SorPoisson sor(*k.ch.dec, k.ch.c.domain, k.work.dp, mode, &k.timers);
  const double factor = 1.0 / k.dt();
  sor.sweeps(k.work.div, 1, factor);  // warm-up: MPI connections, first pass
  const int passes = sor_passes_per_sweep(k.ch.dec->dims());
  const PerCell halo{(double(passes) * kSorSweeps + 1) / kSorSweeps * halo_bytes_per_cell(sor.halo(), k.cells()), 0};
  KernelCost cost = k.cost(sor_sweep_cost(passes) + halo);
  cost.units = kSorSweeps;  // times and counters per sweep
  bench::time_kernel(state, cost, 1, [&] { sor.sweeps(k.work.div, kSorSweeps, factor); });
}

// fft_solve_cost(NX, NZ): 304 B and 2 x 2.5 log2 NX + (NX/2+1)/NX (10 log2 NZ + 17) flops.
void BM_FftSolve(benchmark::State& state, int n) {
  KernelSetup& k = kernel_setup(n);
  FftPoisson fft(*k.ch.dec, k.ch.c.domain, fft_planning(), &k.timers);
  const double factor = 1.0 / k.dt();
  fft.solve(k.work.div, k.work.dp, factor);  // warm-up
  const Int3& g = k.ch.dec->global();
  bench::time_kernel(state, k.cost(fft_solve_cost(g[X], g[Z])), 1,
                     [&] { fft.solve(k.work.div, k.work.dp, factor); });
}

// One multigrid solve to 1e-3 (MgPoisson, hypre's PFMG) from x = 0: hypre's own work is not
// counted from its code, so the cost is the method's increment_work (the rhs in, dp out).
void BM_MgSolve(benchmark::State& state, int n) {
  KernelSetup& k = kernel_setup(n);
  MgPoisson mg(*k.ch.dec, k.ch.c.domain, &k.timers);
  const double factor = 1.0 / k.dt();
  const MgStop stop{1e-3, 1000};
  mg.solve(k.work.div, k.work.dp, factor, stop);  // warm-up
  const MethodChoice mg_choice = configure_method("mg", {}, std::nullopt);
  const IncrementWork w = mg_choice.spec->increment_work(mg_choice, k.ch.dec->global(), k.ch.dec->dims());
  bench::time_kernel(state, k.cost(w.kernels), 1, [&] { mg.solve(k.work.div, k.work.dp, factor, stop); });
}

// halo_bytes_per_cell: 4 x MPI bytes + 2 x local bytes per exchange; no flops.
void BM_HaloExchange(benchmark::State& state, int n, CommMode mode) {
  KernelSetup& k = kernel_setup(n);
  HaloExchange halo(*k.ch.dec, k.state().all(), Reach::full, &k.timers);
  halo.exchange();  // warm-up
  const KernelCost cost = k.cost({halo_bytes_per_cell(halo, k.cells()), 0});
  if (mode == CommMode::sync) {
    bench::time_kernel(state, cost, 1, [&] { halo.exchange(); });
  } else {
    bench::time_kernel(state, cost, 1, [&] {
      halo.begin();
      halo.finish();
    });
  }
  state.counters["local_bytes"] = static_cast<double>(halo.bytes_copied_local());
}

// FsiSolver::check_blow_up's MPI_Allreduce of 2 doubles (MPI_MAX): 16 B per call on each
// rank, no flops; reported per call (the cells counter is 1: one call).
void BM_GlobalReduction(benchmark::State& state) {
  const double local[2] = {1.0, 2.0};
  double global[2] = {0, 0};
  bench::time_kernel(state, KernelCost{1, 16, 0}, kReductions, [&] {
    MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    benchmark::DoNotOptimize(global);
  });
}

// One step: the sum of its kernels' counts (kernel_costs.hpp) and halo traffic (StepHalos):
//   every method: stress + momentum (fused where the step takes them fused) + transport
//   (each with its Euler update) + divergence + projection; the state
//   exchange (11 fields, 26 neighbours), the v* exchange and the D* exchange (faces);
//   + the method's increment as it counts it (MethodSpec::increment_work), with its
//   exchanges of a cell field's faces;
//   + nc Crank-Nicolson sweeps when the method has them (each a v* exchange of 26
//   neighbours and a tau exchange of faces, one more v* exchange at the end).
PerCell step_cost(const StepCase& m, const Int3& global, const Int3& dims, const StepHalos& h) {
  // Stress and momentum fused where no Crank-Nicolson reads tau and the step runs whole (sync,
  // or async with every neighbour the rank itself); FsiSolver::tendencies.
  const bool messages = dims[X] * dims[Y] * dims[Z] > 1;
  const bool fused = m.choice.cn_sweeps == 0 && (m.mode == CommMode::sync || !messages);
  PerCell c = (fused ? kStressAndMomentum : kStress + kMomentum) + kTransport +
              kDivergence + kProject;
  c = c + PerCell{h.state + h.vstar_faces + h.cell_faces, 0};
  const IncrementWork inc = m.choice.spec->increment_work(m.choice, global, dims);
  c = c + inc.kernels + PerCell{inc.cell_face_exchanges * h.cell_faces, 0};
  const int nc = m.choice.cn_sweeps;
  if (nc > 0) c = c + crank_nicolson_cost(nc) + PerCell{nc * (h.vstar_full + h.tau_faces) + h.vstar_full, 0};
  return c;
}

void BM_Step(benchmark::State& state, const StepCase& m, int n) {
  const KernelSetup& k = kernel_setup(n);  // first: a new size drops the step set-up
  const std::string key = bench::step_case_name(m) + "/" + std::to_string(n);
  if (!g_step || g_step_key != key) {
    g_step.reset();
    g_step = std::make_unique<bench::ChannelSetup>(m, n, timed_planning());
    g_step_key = key;
    g_step->solver->impose_laminar_flow();
    g_step->solver->step();  // warm-up: first touch, FFTW and MPI set-up
  }
  FsiSolver& solver = *g_step->solver;
  const PerCell cost = step_cost(m, g_step->dec->global(), g_step->dec->dims(), k.halos);
  bench::time_kernel(state, k.cost(cost, kTransportWenoFlops), 1, [&] { solver.step(); });
}

[[maybe_unused]] const bool kRegistered = [] {
  using Fn = std::function<void(benchmark::State&)>;
  auto reg = [](const std::string& name, Fn f) {
    auto* b = benchmark::RegisterBenchmark(name.c_str(), [f, name](benchmark::State& s) {
      bench::set_kernel_name(name);
      f(s);
    });
    b->UseManualTime()->Unit(benchmark::kMicrosecond);
    if (bench::count_mode()) b->Iterations(1)->Repetitions(1);
  };
  for (int n : kSizes) {
    const std::string sz = std::string("/").append(std::to_string(n));  // not "/" + string&&: GCC 12 -Wrestrict
    reg("BM_Stress" + sz, [n](benchmark::State& s) { BM_Stress(s, n); });
    reg("BM_MomentumRhs" + sz, [n](benchmark::State& s) { BM_MomentumRhs(s, n); });
    reg("BM_Transport" + sz, [n](benchmark::State& s) { BM_Transport(s, n); });
    reg("BM_AcmMoments" + sz, [n](benchmark::State& s) { BM_AcmMoments(s, n); });
    reg("BM_AcmIncrement" + sz, [n](benchmark::State& s) { BM_AcmIncrement(s, n); });
    reg("BM_SorSweep/sync" + sz, [n](benchmark::State& s) { BM_SorSweep(s, n, CommMode::sync); });
    reg("BM_SorSweep/async" + sz, [n](benchmark::State& s) { BM_SorSweep(s, n, CommMode::async); });
    reg("BM_FftSolve" + sz, [n](benchmark::State& s) { BM_FftSolve(s, n); });
    reg("BM_MgSolve" + sz, [n](benchmark::State& s) { BM_MgSolve(s, n); });
    reg("BM_HaloExchange/sync" + sz, [n](benchmark::State& s) { BM_HaloExchange(s, n, CommMode::sync); });
    reg("BM_HaloExchange/async" + sz, [n](benchmark::State& s) { BM_HaloExchange(s, n, CommMode::async); });
    for (const StepCase& m : bench::step_cases())
      reg("BM_Step/" + bench::step_case_name(m) + sz, [m, n](benchmark::State& s) { BM_Step(s, m, n); });
  }
  reg("BM_GlobalReduction", BM_GlobalReduction);
  return true;
}();

}  // namespace

int main(int argc, char** argv) {
  return efsi::bench::run_main(argc, argv, [] {
    g_step.reset();
    g_kernels.reset();
  });
}
