// channel: one run of any configuration of the channel with particles (docs/architecture.md,
// "Programs and their command lines"). Parses, sets up, times and reports; the physics lives in kernels/.
#include <mpi.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "centroids.hpp"
#include "channel_case.hpp"
#include "config_error.hpp"
#include "driver_support.hpp"
#include "case_run.hpp"
#include "method_options.hpp"
#include "runtime.hpp"
#include "calibration.hpp"
#include "memory_estimate.hpp"
#include "method_registry.hpp"

using namespace efsi;

namespace {

struct Options {
  MethodOptions m;
  std::string cells = "64", length, decomp;
  std::optional<double> t_end, slab, velocity_limit;
  std::optional<int> particles;
  double G = 50.0, force = 1.0, solid_cutoff = 0.0;
  long steps = 50;
  int every = 10, progress = 0;
  std::string profile, series, centroids, csv;
  StateOptions state;
  bool calibrate = false, force_memory = false;
  int max_sweeps = 20000;
};

// "mg, sor": the methods --calibrate takes.
std::string calibrated_methods() {
  std::string out;
  for (const MethodSpec* m : pressure_methods())
    if (m->calibrated_count()) out += (out.empty() ? "" : ", ") + m->name();
  return out;
}

// --calibrate: the method's iteration count on a developed state, as the paper counted
// N_S (calibration.hpp), one rank.
int run_calibration(const Options& o, const ChannelCase& c, const std::vector<Particle>& particles) {
  const CalibratedCount what = *c.method.spec->calibrated_count();
  check_writable(o.series, "--series");
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  CartDecomposition dec(MPI_COMM_WORLD, c.domain.cells, kTransportHalo, rank_grid(c, ranks));
  check_node_memory(calibration_memory(c, dec.local(), dec.dims()), o.force_memory);
  const std::optional<double> given = o.m.method_values.at("--eps");
  std::vector<double> eps;
  if (given) eps.push_back(*given);
  else
    for (const auto& s : paper::kCalibratedSorSweeps) eps.push_back(s.eps);
  std::printf("calibrate: %s cells, box %.4g x %.4g x %.4g, %zu particles, G=%g, dt=%g, N_C=%d\n"
              "  state: laminar Poiseuille flow with the particles at rest and unstrained, then %ld steps of the "
              "FFT reference; rhs = D*/dt of the next step, %s\n",
              to_string(c.domain.cells).c_str(), c.domain.length[0], c.domain.length[1], c.domain.length[2],
              particles.size(), c.solver.physics.G, c.solver.dt, c.solver.cn_sweeps, o.steps, what.procedure.c_str());
  const Calibration cal = calibrate(c, dec, particles, o.steps, eps, o.max_sweeps);
  std::printf("  initial RMS residual %.6g; after %zu %s %.3g of it, max |dp_%s - dp_fft| = %.3g of max |dp_fft|\n",
              cal.initial_residual, cal.history.size(), what.unit.c_str(),
              cal.history.empty() ? 1.0 : cal.history.back(), c.method.name().c_str(), cal.fft_difference);
  bool reached = true;
  for (std::size_t e = 0; e < eps.size(); ++e) {
    if (cal.iterations[e] < 0) {
      std::printf("  eps %g: not reached in --max-sweeps %d\n", eps[e], o.max_sweeps);
      reached = false;
    } else {
      std::printf("  eps %g: %s %d\n", eps[e], what.flag.c_str(), cal.iterations[e]);
    }
  }
  if (!o.series.empty()) {
    std::ostringstream t;
    t << "iteration,relative_residual\n";
    for (std::size_t m = 0; m < cal.history.size(); ++m) t << m + 1 << ',' << cal.history[m] << '\n';
    write_on_root([&] { write_text_file(o.series, t.str()); });
  }
  return reached ? 0 : 4;
}

int run(const Options& o) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);

  ChannelCase c;
  c.domain.cells = parse_int3(o.cells, "--cells");
  if (o.length.empty()) {
    for (int a = 0; a < 3; ++a) c.domain.length[a] = c.domain.cells[a] * paper::kSpacing;
  } else {
    c.domain.length = parse_double3(o.length, "--length");
  }
  apply_method_options(o.m, c, paper::kAcmDt, o.calibrate);
  if (o.calibrate && !c.method.spec->calibrated_count())
    throw ConfigError("--calibrate applies to a method with an iteration count per step (" + calibrated_methods() +
                      "), not --method " + c.method.name());
  if (o.max_sweeps < 1) throw ConfigError("--max-sweeps " + std::to_string(o.max_sweeps) + " must be at least 1");
  apply_physics_options(o.G, o.force, o.solid_cutoff, c);
  if (o.progress < 0) throw ConfigError("--progress " + std::to_string(o.progress) + " must be zero or positive");
  if (o.particles && *o.particles < 0)
    throw ConfigError("--particles " + std::to_string(*o.particles) + " must be zero or positive");
  if (o.slab && !(*o.slab > 0)) throw ConfigError("--slab " + std::to_string(*o.slab) + " must be positive");
  if (o.velocity_limit && !(*o.velocity_limit > 0))
    throw ConfigError("--velocity-limit " + std::to_string(*o.velocity_limit) + " must be positive");
  c.slab = o.slab.value_or(0.0);
  if (o.particles) {
    c.particles = *o.particles;
  } else {
    // Default: every lattice site when the box is whole lattice cells and holds no slab.
    c.particles = 0;
    if (c.slab == 0) try {
        c.particles = static_cast<int>(lattice_site_count(c.domain, c.particle));
      } catch (const ConfigError&) {
      }
  }
  if (!o.decomp.empty()) c.forced_dims = parse_int3(o.decomp, "--decomp");
  if (o.every < 1) throw ConfigError("--every " + std::to_string(o.every) + " must be at least 1");
  c.solver.velocity_limit = o.velocity_limit.value_or(default_velocity_limit(c));

  long total = o.steps + 1;  // one warm-up step, then the measured ones
  if (o.t_end) {
    total = std::lround(*o.t_end / c.solver.dt);
    if (total < 2) throw ConfigError("--t-end " + std::to_string(*o.t_end) + " is under two steps of dt");
  } else if (o.steps < 1) {
    throw ConfigError("--steps " + std::to_string(o.steps) + " must be at least 1");
  }

  const std::vector<Particle> particles = validate_case(c, ranks, double(total) * c.solver.dt);
  if (o.calibrate) {
    if (ranks != 1) throw ConfigError("--calibrate runs on one rank (the paper's procedure); started on " +
                                      std::to_string(ranks));
    return run_calibration(o, c, particles);
  }
  RunRequest req;
  req.program = "channel";
  req.experiment = c.slab > 0 ? "layered" : "channel";
  req.total_steps = total;
  req.every = o.every;
  req.progress = o.progress;
  req.series = o.series, req.centroids = o.centroids, req.profile = o.profile, req.csv = o.csv;
  req.force_memory = o.force_memory;
  apply_state_options(o.state, req);
  return run_case(c, particles, req).valid ? 0 : 4;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"One run of the explicit full-Eulerian FSI channel (docs/architecture.md, 'Programs and their command lines').\n"
               "One warm-up step precedes the measured --steps; --t-end counts every step.",
               "channel"};
  app.add_option("--cells", o.cells, "N or NX,NY,NZ cells")->capture_default_str();
  app.add_option("--length", o.length, "L or LX,LY,LZ box lengths (default: 3.6/64 per cell)");
  add_method_options(app, o.m, "1.25e-5");
  app.add_flag("--calibrate", o.calibrate,
               calibrated_methods() + ", one rank: count the iterations (sweeps, V-cycles) to reach --eps (default: "
               "1e-3 and 1e-4) on a developed state (--steps FFT steps from laminar flow) and exit; --series "
               "writes the residual history");
  app.add_option("--max-sweeps", o.max_sweeps, "--calibrate gives up after this many iterations")->capture_default_str();
  auto* steps = app.add_option("--steps", o.steps, "measured steps")->capture_default_str();
  app.add_option("--t-end", o.t_end, "run to this time instead of --steps")->excludes(steps);
  app.add_option("--G", o.G, "shear modulus")->capture_default_str();
  app.add_option("--force", o.force, "driving pressure gradient along x")->capture_default_str();
  app.add_option("--solid-cutoff", o.solid_cutoff,
                 "reset Bt to unstrained where phi is below this (interface debris; 0: the paper's method)")
      ->capture_default_str();
  app.add_option("--particles", o.particles,
                 "first K lattice sites (0: none; default: all sites when the box is whole 3.6 lattice cells)");
  app.add_option("--slab", o.slab, "layered case: solid for A < y < Ly - A");
  app.add_option("--decomp", o.decomp, "force PX,PY,PZ ranks (0 entries free)");
  app.add_option("--profile", o.profile, "write x-z means against y at the end: y,u,phi,Bt11,Bt12");
  app.add_option("--series", o.series, "write diagnostics every --every steps");
  app.add_option("--centroids", o.centroids, "write particle centroids every --every steps");
  app.add_option("--every", o.every, "steps between series rows")->capture_default_str();
  app.add_option("--csv", o.csv, "append the run's result row to this CSV file");
  app.add_option("--progress", o.progress, "print progress every N steps (default: 20 times in long runs)");
  add_state_options(app, o.state);
  app.add_option("--velocity-limit", o.velocity_limit, "blow-up bound (default: 100 x laminar centre velocity)");
  add_force_memory_flag(app, o.force_memory);
  return run_driver(argc, argv, app, [&] { return run(o); });
}
