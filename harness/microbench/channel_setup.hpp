#pragma once
// The paper's weak-scaling channel block for the micro-benchmarks: `block`^3 cells of 3.6^3
// per rank (one lattice cell, two body-centred particles), ranks side by side in x (global
// cells {block P, block, block}, box {3.6 P, 3.6, 3.6}), G = 50, built the way every driver
// builds a run: weak_block_case -> validate_case -> CartDecomposition -> build_solver.
// bench_step uses it at block 64; bench_kernels at 32 and 64 (the box stays 3.6^3 per rank,
// so 32^3 has twice the spacing and the same particles).
#include <mpi.h>

#include <memory>
#include <string>
#include <vector>

#include "channel_case.hpp"
#include "decomposition.hpp"
#include "fsi_solver.hpp"
#include "fsi_state.hpp"
#include "particles.hpp"

namespace efsi::bench {

// One method's settings for a whole step.
struct StepCase {
  std::string method;  // a registered pressure method
  CommMode mode;
  double dt;
  int ns;              // SOR sweeps per step (method sor)
  int nc;              // Crank-Nicolson sweeps per step; 0: explicit stress
  int steps_per_iter;  // steps timed together in one benchmark iteration
};

// The paper's three methods in both communication modes (FFT: sync only), as bench_step
// runs them: ACM dt 1.25e-5 explicit stress; SOR dt 6.25e-5, N_S = 213 (eps 1e-3 at 64^3),
// Crank-Nicolson stress by N_C = 20 sweeps; FFT dt 6.25e-5, explicit stress.
inline const std::vector<StepCase>& paper_step_cases() {
  static const std::vector<StepCase> cases{
      {"acm", CommMode::sync, paper::kAcmDt, 0, 0, 5},
      {"acm", CommMode::async, paper::kAcmDt, 0, 0, 5},
      {"sor", CommMode::sync, paper::kSmacDt, paper::kCalibratedSorSweeps[0].sweeps, paper::kCnSweeps, 2},
      {"sor", CommMode::async, paper::kSmacDt, paper::kCalibratedSorSweeps[0].sweeps, paper::kCnSweeps, 2},
      {"fft", CommMode::sync, paper::kSmacDt, 0, 0, 5},
  };
  return cases;
}

// "acm/sync", "sor_ns213_nc20/async", "fft/sync".
inline std::string step_case_name(const StepCase& m) {
  std::string name = m.method;
  if (m.ns > 0) name += "_ns" + std::to_string(m.ns) + "_nc" + std::to_string(m.nc);
  else if (m.nc > 0) name += "_nc" + std::to_string(m.nc);
  return name + "/" + to_string(m.mode);
}

struct ChannelSetup {
  ChannelCase c;
  std::vector<Particle> particles;
  std::unique_ptr<CartDecomposition> dec;
  std::unique_ptr<FsiSolver> solver;

  ChannelSetup(const StepCase& m, int block, bool timed_planning = true) {
    int p = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &p);
    c = weak_block_case(block, p);
    c.solver.dt = m.dt;
    c.solver.comm = m.mode;
    OptionValues given;
    if (m.ns > 0) given["--ns"] = m.ns;
    choose_method(c, configure_method(m.method, given, m.nc));
    c.timed_planning = timed_planning;
    // t_end only bounds the a-priori velocity for the time-step check: a generous run length.
    particles = validate_case(c, p, 1000 * m.dt);
    dec = std::make_unique<CartDecomposition>(MPI_COMM_WORLD, c.domain.cells, kTransportHalo, c.forced_dims);
    solver = build_solver(c, *dec, particles);
  }
};

}  // namespace efsi::bench
