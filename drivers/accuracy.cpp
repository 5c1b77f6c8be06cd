// accuracy: the paper's accuracy comparison (section 3.1, docs/numerics.md, "Experiments"): the same
// case with particles run with ACM and with the exact FFT reference; time series of the
// energy budget and the particle centroids, final phi fields as VTK image data, and the
// differences between the two at the end.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <utility>

#include "case_run.hpp"
#include "centroids.hpp"
#include "config_error.hpp"
#include "driver_support.hpp"
#include "field_gather.hpp"
#include "memory_estimate.hpp"
#include "method_options.hpp"
#include "runtime.hpp"
#include "snapshot.hpp"
#include "state_options.hpp"

using namespace efsi;

namespace {

struct Options {
  int cells = 128, threads = 0;
  double length = 7.2, G = 50.0, dt = 5e-4, t_end = 20.0, force = 1.0;
  // Without it the case blows up in the particles' debris near the walls at t = 6.6, and
  // with 0.01 in the band just above it at t = 14.8 (docs/numerics.md, "Solid cut-off").
  double solid_cutoff = 0.05;
  std::optional<int> every, particles;
  std::string methods = "acm,fft", out = ".", csv;
  bool force_memory = false, reproducible = false;
  StateOptions state;
};

// Largest distance from a region of `a` to the nearest region of `b`, periodic in x and z.
double centroid_mismatch(const std::vector<SolidRegion>& a, const std::vector<SolidRegion>& b, const Domain& d) {
  double worst = 0.0;
  for (const SolidRegion& ra : a) {
    double best = INFINITY;
    for (const SolidRegion& rb : b) {
      double s = 0.0;
      for (int ax = 0; ax < 3; ++ax) {
        double diff = std::fabs(ra.centroid[ax] - rb.centroid[ax]);
        if (ax != Y) diff = std::min(diff, d.length[ax] - diff);
        s += diff * diff;
      }
      best = std::min(best, std::sqrt(s));
    }
    worst = std::max(worst, best);
  }
  return a.size() == b.size() ? worst : INFINITY;
}

int run(const Options& o) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  if (o.threads < 0)
    throw ConfigError("--threads " + std::to_string(o.threads) + " must be positive (0: OMP_NUM_THREADS)");
  set_threads(o.threads);
  // Each method with its defaults (the paper's N_C for sor, explicit stress otherwise).
  std::vector<MethodChoice> methods;
  std::stringstream ss(o.methods);
  for (std::string m; std::getline(ss, m, ',');) methods.push_back(configure_method(m, {}, std::nullopt));
  if (methods.empty()) throw ConfigError("--methods '" + o.methods + "' names no method");
  if (o.cells < 1) throw ConfigError("--cells " + std::to_string(o.cells) + " must be at least 1");
  if (!(o.length > 0)) throw ConfigError("--length " + std::to_string(o.length) + " must be positive");
  check_time_step_value(o.dt, "--dt");
  const long total = std::lround(o.t_end / o.dt);
  if (total < 2) throw ConfigError("--t-end " + std::to_string(o.t_end) + " is under two steps of --dt");
  const int every = o.every.value_or(static_cast<int>(std::max(1L, total / 400)));
  if (every < 1) throw ConfigError("--every " + std::to_string(every) + " must be at least 1");

  ChannelCase c;
  c.domain.cells = {o.cells, o.cells, o.cells};
  c.domain.length = {o.length, o.length, o.length};
  c.solver.dt = o.dt;
  apply_physics_options(o.G, o.force, o.solid_cutoff, c);
  c.timed_planning = !o.reproducible;
  c.particles = o.particles ? *o.particles : static_cast<int>(lattice_site_count(c.domain, c.particle));
  c.solver.velocity_limit = default_velocity_limit(c);
  const std::string dir = o.out.empty() ? "." : o.out;
  check_writable(dir + "/comparison.txt", "--out");
  check_csv(o.csv);

  // Every method's set-up is checked before the first one runs: a run of hours must not be
  // followed by a configuration error. Every method's solver stays alive to the comparison at
  // the end, so the node must hold them all at once.
  std::vector<std::vector<Particle>> particles;
  std::size_t bytes = 0;
  for (const MethodChoice& m : methods) {
    choose_method(c, m);
    particles.push_back(validate_case(c, ranks, double(total) * c.solver.dt));
    const Int3 dims = rank_grid(c, ranks);
    Int3 local{};
    for (int a = 0; a < 3; ++a) local[a] = c.domain.cells[a] / dims[a];
    bytes += estimate_rank_memory(c, local, dims).total();
  }
  check_node_memory(bytes, o.force_memory);

  // Every method's outputs (and restart file) are checked before the first method runs.
  std::vector<RunRequest> requests;
  for (const MethodChoice& m : methods) {
    const std::string tag = m.name();
    RunRequest req;
    req.program = "accuracy";
    req.experiment = "accuracy";
    req.total_steps = total;
    req.every = every;
    req.series = dir + "/series-" + tag + ".csv";
    req.centroids = dir + "/centroids-" + tag + ".csv";
    // The rows are appended at the end, after comparison.txt: none is recorded for a run
    // whose outputs were not all written.
    //
    // The node's memory was checked above for every method together. Checked again here,
    // against what the earlier methods left available, the estimate's margin alone could
    // refuse a later method after hours of the first.
    req.memory_checked = true;
    StateOptions state = o.state;
    if (state.snapshot_prefix.empty()) state.snapshot_prefix = dir + "/snapshot";
    apply_state_options(state, req, tag);
    check_outputs(req);
    requests.push_back(std::move(req));
  }

  std::vector<RunOutcome> runs;
  std::vector<std::vector<SolidRegion>> regions;
  std::vector<std::vector<double>> phi_global;  // on rank 0: the methods may run on different rank grids
  for (std::size_t k = 0; k < methods.size(); ++k) {
    choose_method(c, methods[k]);
    const std::string tag = c.method.name();
    runs.push_back(run_case(c, particles[k], requests[k]));
    const CartDecomposition& dec = *runs.back().decomp;
    const Field& phi = runs.back().solver->state().phi();
    regions.push_back(solid_regions(phi, c.domain, dec));
    phi_global.push_back(gather_global(phi, dec));
    write_snapshot(dir + "/fields-" + tag + ".h5", std::as_const(runs.back().solver->state()).all(), dec, c.domain,
                   runs.back().solver->steps_done(),
                   runs.back().solver->time());
  }

  // The differences at the end against the first method (ACM against the FFT reference).
  std::string text;
  for (std::size_t r = 1; r < runs.size(); ++r) {
    double phi_diff = 0.0;
    for (std::size_t p = 0; p < phi_global[r].size(); ++p)
      phi_diff = std::max(phi_diff, std::fabs(phi_global[0][p] - phi_global[r][p]));
    const FlowDiagnostics da = runs[0].solver->diagnostics(), db = runs[r].solver->diagnostics();
    auto rel = [](double x, double y) { return std::fabs(x - y) / std::max(std::fabs(y), 1e-300); };
    char b2[512];
    std::snprintf(b2, sizeof b2,
                  "%s against %s at t = %.6g: max |phi diff| %.3g; centroids %.3g cells apart at most; relative "
                  "differences K %.3g, I %.3g, eps_s %.3g, eps_f %.3g\n",
                  methods[0].name().c_str(), methods[r].name().c_str(), da.time, phi_diff,
                  centroid_mismatch(regions[0], regions[r], c.domain) / c.domain.spacing(X),
                  rel(da.kinetic, db.kinetic), rel(da.input, db.input), rel(da.eps_solid, db.eps_solid),
                  rel(da.eps_fluid, db.eps_fluid));
    text += b2;
  }
  bool valid = true;
  for (const RunOutcome& r : runs) valid = valid && r.valid;
  if (is_root()) std::fputs(text.c_str(), stdout);
  write_on_root([&] {
    // One method alone (a job per method, compared afterwards from the files by
    // plots/make_plots.py) has nothing to compare.
    if (runs.size() > 1) write_text_file(dir + "/comparison.txt", text);
    if (!o.csv.empty())
      for (const RunOutcome& r : runs) append_csv(o.csv, r.record);
  });
  return valid ? 0 : 4;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "The paper's accuracy comparison (section 3.1; docs/numerics.md, 'Experiments'): 16 particles in 7.2^3 on 128^3 "
      "cells, G = 50, dt = 5e-4 to t = 20, with ACM and the FFT reference.\nWrites into --out: "
      "series-<method>.csv (energy budget), centroids-<method>.csv, fields-<method>.h5 with .xmf (every state field "
      "at the end: parallel HDF5, ParaView) and "
      "comparison.txt. Smaller and shorter runs: --cells, --t-end.\nEach method's checkpoint and snapshots take "
      "-<method> into their names: --checkpoint run/ck.h5 writes run/ck-acm.h5 and run/ck-fft.h5, and --restart "
      "run/ck.h5 reads them.",
      "accuracy"};
  app.add_option("--cells", o.cells, "cells along each axis")->capture_default_str();
  app.add_option("--length", o.length, "box length along each axis")->capture_default_str();
  app.add_option("--particles", o.particles, "first K lattice sites (default: all, 16 in 7.2^3)");
  app.add_option("--methods", o.methods, "pressure methods, comma-separated; the first is compared with the others")
      ->capture_default_str();
  app.add_option("--G", o.G, "shear modulus")->capture_default_str();
  app.add_option("--force", o.force, "driving pressure gradient along x (the paper's quoted CFL 0.018 and Re 10 imply about 0.31)")
      ->capture_default_str();
  app.add_option("--solid-cutoff", o.solid_cutoff,
                 "reset Bt to unstrained where phi is below this (interface debris; 0: the paper's method)")
      ->capture_default_str();
  app.add_option("--dt", o.dt, "time step")->capture_default_str();
  app.add_option("--t-end", o.t_end, "end time (every step is measured after one warm-up step)")->capture_default_str();
  app.add_option("--every", o.every, "steps between series and centroid rows (default: 400 rows)");
  app.add_option("--out", o.out, "existing directory for the outputs")->capture_default_str();
  app.add_option("--csv", o.csv, "append one result row per method to this CSV file");
  app.add_option("--threads", o.threads, "OpenMP threads per rank (default: OMP_NUM_THREADS)");
  add_reproducible_flag(app, o.reproducible);
  add_force_memory_flag(app, o.force_memory);
  o.state.snapshot_prefix = "";  // OUT/snapshot unless given
  add_state_options(app, o.state);
  return run_driver(argc, argv, app, [&] { return run(o); });
}
