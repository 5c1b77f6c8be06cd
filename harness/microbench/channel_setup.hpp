#pragma once
// The paper's weak-scaling channel block for the micro-benchmarks: `block`^3 cells of 3.6^3
// per rank (one lattice cell, two body-centred particles), ranks side by side in x (global
// cells {block P, block, block}, box {3.6 P, 3.6, 3.6}), G = 50, built the way every driver
// builds a run: weak_block_case -> validate_case -> CartDecomposition -> build_solver.
// bench_step uses it at block 64; bench_kernels at 32 and 64 (the box stays 3.6^3 per rank,
// so 32^3 has twice the spacing and the same particles).
#include <mpi.h>

#include <algorithm>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "channel_case.hpp"
#include "decomposition.hpp"
#include "fsi_solver.hpp"
#include "fsi_state.hpp"
#include "method_registry.hpp"
#include "particles.hpp"

namespace efsi::bench {

// One method's settings for a whole step.
struct StepCase {
  MethodChoice choice;  // a registered method, configured
  CommMode mode;
  double dt;
  int steps_per_iter;  // steps timed together in one benchmark iteration
};

// Every registered method in every halo mode it takes, at the paper's time step and its
// first campaign variant (SOR: eps 1e-3, the calibrated N_S = 213 at 64^3), with its
// default stress (ACM and FFT explicit, SOR Crank-Nicolson with N_C = 20).  A method with
// the paper's 50 steps times 5 per iteration, one with 10 steps one.
inline const std::vector<StepCase>& step_cases() {
  static const std::vector<StepCase> cases = [] {
    std::vector<StepCase> out;
    for (const MethodSpec* spec : pressure_methods()) {
      OptionValues given;
      const std::vector<CampaignVariant> variants = spec->campaign_variants();
      if (!variants.empty())
        for (std::size_t a = 0; a + 1 < variants[0].args.size(); a += 2)
          given[variants[0].args[a]] = std::stod(variants[0].args[a + 1]);
      const MethodChoice choice = configure_method(spec->name(), given, std::nullopt);
      const ScalingDefaults d = spec->scaling_defaults();
      for (CommMode mode : {CommMode::sync, CommMode::async})
        if (spec->supports(mode)) out.push_back({choice, mode, d.dt, static_cast<int>(std::max(1L, d.steps / 10))});
    }
    return out;
  }();
  return cases;
}

// "acm/sync", "sor_ns213_nc20/async", "fft/sync": the method, its per-step SOR sweeps (a
// method that reports ns_per_step) and Crank-Nicolson sweeps, the halo mode.
inline std::string step_case_name(const StepCase& m) {
  std::string name = m.choice.name();
  const auto ns = m.choice.report.find("ns_per_step");
  if (ns != m.choice.report.end()) name += "_ns" + ns->second + "_nc" + std::to_string(m.choice.cn_sweeps);
  else if (m.choice.cn_sweeps > 0) name += "_nc" + std::to_string(m.choice.cn_sweeps);
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
    choose_method(c, m.choice);
    c.timed_planning = timed_planning;
    // t_end only bounds the a-priori velocity for the time-step check: a generous run length.
    particles = validate_case(c, p, 1000 * m.dt);
    dec = std::make_unique<CartDecomposition>(MPI_COMM_WORLD, c.domain.cells, kTransportHalo, c.forced_dims);
    solver = build_solver(c, *dec, particles);
  }
};

}  // namespace efsi::bench
