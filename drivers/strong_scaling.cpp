// strong_scaling: the paper's strong-scaling case (section 3.3, docs/numerics.md, "Experiments"),
// 2048 x 1024 x 1024 cells in 115.2 x 57.6 x 57.6 with 16384 particles, or a copy scaled
// down by --scale per direction at the same particle density; --dry-run says what any
// rank count would need without allocating the case.
#include <mpi.h>

#include <cstdio>

#include "case_run.hpp"
#include "config_error.hpp"
#include "decomposition.hpp"
#include "driver_support.hpp"
#include "memory_estimate.hpp"
#include "method_options.hpp"

using namespace efsi;

namespace {

constexpr Int3 kFullCells{2048, 1024, 1024};
constexpr int kLatticeCellsAcross = 16;  // 57.6 / 3.6: the scale must keep whole lattice cells

struct Options {
  MethodOptions m;
  int scale = 1;
  std::optional<long> steps;
  bool dry_run = false, force_memory = false;
  std::optional<int> dry_ranks;
  std::string decomp, csv;
  StateOptions state;
};

int dry_run(const ChannelCase& c, int ranks, std::size_t particles) {
  const Int3 dims = rank_grid(c, ranks);
  Int3 local{};
  for (int a = 0; a < 3; ++a) local[a] = c.domain.cells[a] / dims[a];
  const MemoryEstimate m = estimate_rank_memory(c, local, dims);
  if (is_root()) {
    std::printf("strong_scaling dry run: %s cells, box %.4g x %.4g x %.4g, %zu particles, %s\n",
                to_string(c.domain.cells).c_str(), c.domain.length[0], c.domain.length[1], c.domain.length[2],
                particles, c.method.name().c_str());
    std::printf("  ranks %d as %s, local block %s (%.4g cells per rank)\n", ranks, to_string(dims).c_str(),
                to_string(local).c_str(), double(product(local)));
    std::printf("  memory per rank: %.3f GiB (%d fields %.3f GiB", gib(double(m.total())), m.fields,
                gib(double(m.field_bytes)));
    if (m.solver_bytes > 0) std::printf(", %s %.3f GiB", c.method.spec->extra_bytes_hold().c_str(), gib(double(m.solver_bytes)));
    std::printf("); all ranks %.4g GiB\n", gib(double(m.total())) * ranks);
  }
  return 0;
}

int run(const Options& o) {
  ChannelCase c;
  const long steps = apply_scaling_defaults(o.m, c, o.steps);
  if (o.scale < 1 || kLatticeCellsAcross % o.scale != 0)
    throw ConfigError("--scale " + std::to_string(o.scale) +
                      " does not divide the case into whole 3.6 lattice cells: " + "it must divide " +
                      std::to_string(kLatticeCellsAcross) + " (1, 2, 4, 8 or 16)");
  for (int a = 0; a < 3; ++a) {
    c.domain.cells[a] = kFullCells[a] / o.scale;
    c.domain.length[a] = c.domain.cells[a] * paper::kSpacing;
  }
  c.particles = static_cast<int>(lattice_site_count(c.domain, c.particle));  // 16384 / scale^3
  if (!o.decomp.empty()) c.forced_dims = parse_int3(o.decomp, "--decomp");
  c.solver.velocity_limit = default_velocity_limit(c);

  if (o.dry_run) {
    if (!o.dry_ranks) throw ConfigError("--dry-run needs --ranks N");
    if (*o.dry_ranks < 1) throw ConfigError("--ranks " + std::to_string(*o.dry_ranks) + " must be at least 1");
    return dry_run(c, *o.dry_ranks, static_cast<std::size_t>(c.particles));
  }
  if (o.dry_ranks) throw ConfigError("--ranks applies to --dry-run only (a run uses the ranks it is started on)");
  return run_scaling_case(c, "strong_scaling", "strong", steps, o.csv, o.force_memory, o.state);
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "The paper's strong-scaling case (docs/numerics.md, 'Experiments', and docs/architecture.md, 'Programs and their command lines'): 2048 x 1024 x 1024 cells, "
      "115.2 x 57.6 x 57.6, 16384 particles; --scale S divides every length and count by S per "
      "direction (particles at the same density).\nSteps as in weak scaling, each method's own (--list-methods). --dry-run --ranks N prints the decomposition, local block and memory per rank "
      "for N ranks and exits without allocating the case.",
      "strong_scaling"};
  app.add_option("--scale", o.scale, "divide the case by S per direction (1, 2, 4, 8 or 16)")->capture_default_str();
  add_method_options(app, o.m, scaling_dt_help());
  app.add_option("--steps", o.steps, "measured steps (default: " + scaling_steps_help() + ")");
  app.add_option("--decomp", o.decomp, "force PX,PY,PZ ranks (0 entries free)");
  app.add_flag("--dry-run", o.dry_run, "print decomposition, local block and memory per rank for --ranks, then exit");
  app.add_option("--ranks", o.dry_ranks, "rank count for --dry-run");
  app.add_option("--csv", o.csv, "append the run's result row to this CSV file");
  add_force_memory_flag(app, o.force_memory);
  add_state_options(app, o.state);
  return run_driver(argc, argv, app, [&] { return run(o); });
}
