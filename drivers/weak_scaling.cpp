// weak_scaling: the paper's weak-scaling experiment (section 3.2, docs/numerics.md, "Experiments") on
// however many ranks it is started with: a fixed block and particle count per rank, the
// global box the rank grid times the block, walls bounding the outermost ranks in y.
#include <mpi.h>

#include "case_run.hpp"
#include "config_error.hpp"
#include "decomposition.hpp"
#include "driver_support.hpp"
#include "method_options.hpp"

using namespace efsi;

namespace {

struct Options {
  MethodOptions m;
  int local = 64, particles_per_rank = 2;
  std::optional<long> steps;
  std::string decomp, csv;
  bool force_memory = false;
  StateOptions state;
};

int run(const Options& o) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  ChannelCase c;
  // The method's own steps and time step (MethodSpec::scaling_defaults).
  const long steps = apply_scaling_defaults(o.m, c, o.steps);
  if (o.local < 1) throw ConfigError("--local " + std::to_string(o.local) + " must be at least 1");
  if (o.particles_per_rank < 0)
    throw ConfigError("--particles-per-rank " + std::to_string(o.particles_per_rank) + " must be zero or positive");

  Int3 dims{0, 0, 0};
  if (!o.decomp.empty()) {
    dims = parse_int3(o.decomp, "--decomp");
    if (product(dims) != ranks)
      throw ConfigError("--decomp " + o.decomp + " has " + std::to_string(product(dims)) + " ranks, started on " +
                        std::to_string(ranks));
  } else {
    dims = choose_block_dims(ranks, {o.local, o.local, o.local});
  }
  c.forced_dims = dims;
  for (int a = 0; a < 3; ++a) {
    c.domain.cells[a] = dims[a] * o.local;
    c.domain.length[a] = c.domain.cells[a] * paper::kSpacing;
  }
  c.particles = o.particles_per_rank * ranks;
  c.solver.velocity_limit = default_velocity_limit(c);

  return run_scaling_case(c, "weak_scaling", "weak", steps, o.csv, o.force_memory, o.state);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "The paper's weak-scaling case (docs/numerics.md, 'Experiments', and docs/architecture.md, 'Programs and their command lines'): a --local^3 block with "
      "--particles-per-rank particles per rank, the global box the rank grid times the block.\n"
      "Defaults are the paper's, each method's own (--list-methods): its time step and measured steps, "
      "and its settings (SOR: N_S from the calibration for --eps, N_C = 20). One warm-up step precedes "
      "the measured ones.",
      "weak_scaling"};
  app.add_option("--local", o.local, "cells per rank along each axis")->capture_default_str();
  app.add_option("--particles-per-rank", o.particles_per_rank,
                 "particles per rank: the first K x ranks sites of the lattice")
      ->capture_default_str();
  add_method_options(app, o.m, scaling_dt_help());
  app.add_option("--steps", o.steps, "measured steps (default: " + scaling_steps_help() + ")");
  app.add_option("--decomp", o.decomp, "rank grid PX,PY,PZ (default: MPI_Dims_create's factors, placed for the least halo traffic: the largest on y, then z)");
  app.add_option("--csv", o.csv, "append the run's result row to this CSV file");
  add_force_memory_flag(app, o.force_memory);
  add_state_options(app, o.state);
  return run_driver(argc, argv, app, [&] { return run(o); });
}
