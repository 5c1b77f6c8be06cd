#include "case_run.hpp"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <optional>
#include <sstream>
#include <utility>

#include "centroids.hpp"
#include "checkpoint.hpp"
#include "compute_model.hpp"
#include "config_error.hpp"
#include "driver_support.hpp"
#include "hybrid_layout.hpp"
#include "memory_estimate.hpp"
#include "mpi_interpose.hpp"
#include "run_record.hpp"
#include "runtime.hpp"
#include "snapshot.hpp"
#include "text_file.hpp"
#include "timing_report.hpp"

namespace efsi {
namespace {

std::string series_header() {
  return "step,time,kinetic,input,eps_solid,eps_fluid,div_rms,div_max,u_max,flow_rate,solid_fraction,beta,gamma,"
         "mach,mach_bound\n";
}

std::string series_row(const FlowDiagnostics& d) {
  char b[512];
  std::snprintf(b, sizeof b, "%ld,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%.9g,%.9g,%.12g,%.9g,%.9g,%.6g,%.6g\n", d.step,
                d.time, d.kinetic, d.input, d.eps_solid, d.eps_fluid, d.div_rms, d.div_max, d.u_max, d.flow_rate,
                d.solid_fraction, d.beta, d.gamma, d.mach, d.mach_bound);
  return b;
}

// x-z means at cell-centre heights; Bt12 (on y faces) averaged to the centres.
std::string profile_text(const FsiState& s) {
  const Domain& dom = s.domain();
  const int ny = dom.cells[Y];
  std::vector<double> local(4 * ny, 0.0), global(4 * ny, 0.0);
  const Int3 n = s.phi().n();
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) {
        const int g = s.phi().offset()[Y] + j;
        local[4 * g + 0] += s.vel(X)(i, j, k);
        local[4 * g + 1] += s.phi()(i, j, k);
        local[4 * g + 2] += s.B(0, 0)(i, j, k);
        local[4 * g + 3] += 0.5 * (s.B(0, 1)(i, j, k) + s.B(0, 1)(i, j + 1, k));
      }
  MPI_Allreduce(local.data(), global.data(), 4 * ny, MPI_DOUBLE, MPI_SUM, s.decomp().comm());
  const double cnt = double(dom.cells[X]) * dom.cells[Z];
  std::ostringstream o;
  o << "y,u,phi,Bt11,Bt12\n";
  char b[160];
  for (int j = 0; j < ny; ++j) {
    std::snprintf(b, sizeof b, "%.9g,%.12g,%.12g,%.12g,%.12g\n", (j + 0.5) * dom.spacing(Y), global[4 * j] / cnt,
                  global[4 * j + 1] / cnt, global[4 * j + 2] / cnt, global[4 * j + 3] / cnt);
    o << b;
  }
  return o.str();
}

// The validation phase's thresholds (docs/numerics.md, "Run-time validation"): a run is
// valid when its fields are finite and every figure is below its limit; otherwise the
// timing is recorded as not valid.
struct ValidationCheck {
  const char* figure;
  double limit;
};
constexpr ValidationCheck kValidationChecks[] = {
    {"div_max*dx/U_max", 1e-2},
    {"energy budget residual of its largest term", 0.02},
};

struct Validation {
  bool finite = false, valid = false;
  double value[std::size(kValidationChecks)] = {};
  bool simulated = false;  // the simulation build: no loop ran, nothing to validate
  std::string line() const;  // "validation: FIGURE = X (limit L), ...: PASSED" (or FAILED)
};

std::string Validation::line() const {
  if (simulated)
    return "validation: not run (simulated on " + node_model().platform +
           ": the stages' loops were modelled, not run; the real build validates this configuration)";
  std::string out = "validation:";
  char b[160];
  for (std::size_t k = 0; k < std::size(kValidationChecks); ++k) {
    std::snprintf(b, sizeof b, "%s %s = %.3g (limit %g)", k ? "," : "", kValidationChecks[k].figure, value[k],
                  kValidationChecks[k].limit);
    out += b;
  }
  if (!finite) out += ", non-finite fields";
  return out + (valid ? ": PASSED" : ": FAILED");
}

// Finite fields, divergence small against the velocity gradients, and the energy budget
// closed over the last three steps (central dK/dt).
Validation validate(const std::vector<FlowDiagnostics>& tail, const Domain& dom) {
  Validation v;
  const FlowDiagnostics& last = tail.back();
  v.finite = std::isfinite(last.kinetic) && std::isfinite(last.div_rms) && std::isfinite(last.u_max);
  const double dx = std::min({dom.spacing(X), dom.spacing(Y), dom.spacing(Z)});
  v.value[0] = last.div_max / (std::max(last.u_max, 1e-300) / dx);
  if (tail.size() >= 3) {
    const auto& a = tail[tail.size() - 3];
    const auto& m = tail[tail.size() - 2];
    const auto& b = tail.back();
    const double dkdt = (b.kinetic - a.kinetic) / (b.time - a.time);
    const double largest =
        std::max({std::fabs(dkdt), std::fabs(m.input), std::fabs(m.eps_solid), std::fabs(m.eps_fluid)});
    v.value[1] = largest > 0 ? std::fabs(-dkdt + m.input - m.eps_solid - m.eps_fluid) / largest : 0.0;
  }
  v.valid = v.finite;
  for (std::size_t k = 0; k < std::size(kValidationChecks); ++k) v.valid = v.valid && v.value[k] < kValidationChecks[k].limit;
  return v;
}

// The run's CSV row (harness/run_record.hpp).
RunRecord run_record(const ChannelCase& c, const RunRequest& req, const CartDecomposition& dec,
                     const HybridLayout& layout, std::size_t particles, const TimerReport& rep, double div_rms,
                     bool valid, double pressure_iterations, double pressure_setup_s) {
  RunRecord r;
  r.experiment = req.experiment;
  r.method = c.method.name();
  r.comm = to_string(c.solver.comm);
  r.halo = to_string(c.solver.halo);
  const auto cell = [&](const char* key) {
    const auto it = c.method.report.find(key);
    return it == c.method.report.end() ? std::string() : it->second;
  };
  r.eps = cell("eps");
  r.ranks = static_cast<int>(product(dec.dims()));
  r.threads = max_threads();
  r.px = dec.dims()[0], r.py = dec.dims()[1], r.pz = dec.dims()[2];
  r.nx = c.domain.cells[0], r.ny = c.domain.cells[1], r.nz = c.domain.cells[2];
  r.particles = static_cast<long>(particles);
  r.steps = req.total_steps - 1;
  r.dt = c.solver.dt;
  r.ns_per_step = cell("ns_per_step");
  r.sweeps_per_exchange = cell("sweeps_per_exchange");
  if (c.solver.cn_sweeps > 0) r.nc_per_step = std::to_string(c.solver.cn_sweeps);
  r.timing = rep;
  r.div_rms = div_rms;
  r.valid = valid;
  r.layout = layout;
  r.integrator = c.solver.integrator;
  r.pressure_iterations = pressure_iterations;
  r.pressure_setup_s = pressure_setup_s;
  if (kSimulated) r.simulated = node_model().platform;
  return r;
}

// Collective: rank 0 writes the files, then the CSV row, so that a row is recorded only for
// a run whose every output was written; a failure ends every rank with OutputError.
void write_outputs(const RunRequest& req, const std::string& profile, const std::string& series,
                   const std::string& centroids, const RunRecord& record) {
  write_on_root([&] {
    for (const auto& [path, text] : {std::pair{&req.profile, &profile}, {&req.series, &series},
                                     {&req.centroids, &centroids}})
      if (!path->empty()) write_text_file(*path, *text);
    if (!req.csv.empty()) append_csv(req.csv, record);
  });
}

}  // namespace

void check_outputs(const RunRequest& req) {
  for (const auto& [path, opt] : {std::pair{&req.profile, "--profile"},
                                  {&req.series, "--series"},
                                  {&req.centroids, "--centroids"},
                                  {&req.checkpoint, "--checkpoint"},
                                  {&req.snapshots, "--snapshot-prefix"}})
    check_writable(*path, opt);
  check_csv(req.csv);
}

namespace {

// `whole`: the caller's particles, or null for the case's own lattice (case_particles).
RunOutcome run_case_with(const ChannelCase& c, const std::vector<Particle>* whole, const RunRequest& req) {
  check_outputs(req);
  init_compute_model();  // the simulation build's node model (compute_model.hpp); nothing otherwise
  use_efficiency_of(c.method.name());
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);

  RunOutcome out;
  out.decomp = std::make_unique<CartDecomposition>(MPI_COMM_WORLD, c.domain.cells, kTransportHalo, rank_grid(c, ranks));
  const CartDecomposition& dec = *out.decomp;
  // Each rank keeps the particles that reach its block.  The case's own lattice lives only
  // in this block, with no MPI call in it: in the simulation build its 8192 ranks then hold
  // one lattice at a time, not 8192.
  std::size_t particle_count = 0;
  std::vector<Particle> particles;
  {
    std::vector<Particle> built;
    const std::vector<Particle>& all = whole ? *whole : (built = case_particles(c));
    particle_count = all.size();
    particles = particles_reaching(all, c.domain, c.particle, dec.offset(), dec.local());
  }
  // Before the banner and the first field: a case too big for the node is refused, not
  // started and killed (or swapping) once it has taken the node's memory.
  if (!req.memory_checked) check_node_memory(c, dec.local(), dec.dims(), req.force_memory);
  CheckpointHeader from;  // step 0 unless restarting
  if (!req.restart.empty()) {
    from = check_checkpoint(req.restart, c, dec);
    if (from.step + 2 > req.total_steps)
      throw ConfigError("--restart '" + req.restart + "' is at step " + std::to_string(from.step) +
                        " and the run ends at step " + std::to_string(req.total_steps) +
                        ": it needs at least a warm-up and a measured step more");
  }
  const long first = from.step;
  const long measured = req.total_steps - first - 1;
  const HybridLayout layout = hybrid_layout(dec.comm(), max_threads());
  if (is_root()) {
    std::printf("%s: %s, %s %s halo, %d ranks as %s, local block %s, %d thread(s) per rank, cores %s%s\n",
                req.program.c_str(), c.method.name().c_str(), to_string(c.solver.comm), to_string(c.solver.halo), ranks,
                to_string(dec.dims()).c_str(), to_string(dec.local()).c_str(), max_threads(), layout.cores.c_str(),
                layout.cores_shared ? " (ranks share cores)" : "");
    if (layout.oversubscribed)
      std::printf(
          "warning: ranks x threads exceed the cores of a node: timings not representative, the row is "
          "marked oversubscribed and not valid\n");
    std::printf("  %s cells, box %.4g x %.4g x %.4g, %zu particles%s, G=%g, dt=%g, %ld steps + 1 warm-up, %s\n",
                to_string(c.domain.cells).c_str(), c.domain.length[0], c.domain.length[1], c.domain.length[2],
                particle_count, c.slab > 0 ? " (layered slab)" : "", c.solver.physics.G, c.solver.dt, measured,
                find_integrator(c.solver.integrator).description.c_str());
    std::string sweeps = c.method.banner;
    if (c.solver.cn_sweeps > 0)
      sweeps += (sweeps.empty() ? "N_C = " : ", N_C = ") + std::to_string(c.solver.cn_sweeps) +
                " Crank-Nicolson sweeps per step";
    if (!sweeps.empty()) std::printf("  %s\n", sweeps.c_str());
    if (!req.restart.empty())
      std::printf("  restarted from %s at step %ld, t = %.9g (written by revision %s)\n", req.restart.c_str(),
                  from.step, from.time, from.revision.c_str());
    std::fflush(stdout);
  }
  out.solver = build_solver(c, dec, particles);
  FsiSolver& solver = *out.solver;

  const bool want_rows = !req.series.empty() || !req.centroids.empty();
  RunHistory history{series_header(), "step,time,region,volume,x,y,z\n"};
  if (!req.restart.empty()) history = restore_checkpoint(req.restart, solver);
  std::string &series = history.series, &centroid_rows = history.centroids;
  auto record = [&]() {
    const FlowDiagnostics d = solver.diagnostics();
    if (!req.series.empty()) series += series_row(d);
    if (!req.centroids.empty()) {
      const std::vector<SolidRegion> regions = solid_regions(solver.state().phi(), c.domain, dec);
      char b[200];
      for (std::size_t r = 0; r < regions.size(); ++r) {
        std::snprintf(b, sizeof b, "%ld,%.9g,%zu,%.9g,%.9g,%.9g,%.9g\n", d.step, d.time, r, regions[r].volume,
                      regions[r].centroid[0], regions[r].centroid[1], regions[r].centroid[2]);
        centroid_rows += b;
      }
    }
    return d;
  };
  // Checkpoints and snapshots between steps, outside the measured time.
  int checkpoints = 0, snapshots = 0;
  double state_output_s = 0.0;
  auto save_state = [&](bool at_end) {
    const long done = solver.steps_done();
    const double t0 = MPI_Wtime();
    if (!req.snapshots.empty() && done % req.snapshot_every == 0) {
      write_snapshot(snapshot_name(req.snapshots, done), std::as_const(solver.state()).all(), dec, c.domain, done,
                     solver.time());
      ++snapshots;
    }
    const bool stepped = done > first;  // a checkpoint of the state it started from adds nothing
    if (!req.checkpoint.empty() && stepped &&
        (at_end || (req.checkpoint_every > 0 && done % req.checkpoint_every == 0))) {
      write_checkpoint(req.checkpoint, c, solver, history, build_revision());
      ++checkpoints;
    }
    state_output_s += MPI_Wtime() - t0;
  };
  if (want_rows && req.restart.empty()) record();
  if (req.restart.empty() && !req.snapshots.empty()) save_state(false);

  solver.step();  // warm-up: first touch of the work arrays, MPI connections
  if (want_rows && solver.steps_done() % req.every == 0) record();
  save_state(false);
  solver.timers().reset();
  const long total = req.total_steps;
  const int progress = req.progress > 0 ? req.progress : (total >= 200 ? int(total / 20) : 0);

  double elapsed = 0.0;
  MpiCensus step_census;    // what this rank sent inside the measured steps
  double iterations = 0.0;  // of the pressure solves, summed over the measured steps
  std::vector<FlowDiagnostics> tail;  // the last three steps, for the energy-budget check
  for (long s = 1; s <= measured; ++s) {
    const long done = first + s + 1;  // the warm-up step came first
    const bool want_series = want_rows && done % req.every == 0;
    const bool want_progress = progress > 0 && done % progress == 0;
    // The simulation build's fields hold no solution (compute_model.hpp): no diagnostics.
    const bool want_diag = !kSimulated && (want_series || want_progress || s + 3 > measured);
    const double t0 = MPI_Wtime();
    const MpiCensus before = mpi_census();
    solver.step();
    // Diagnostics need current ghosts: an async exchange is completed inside the timed
    // step, so that every region the timers count lies within the measured time.  The
    // simulation build completes it in the same steps, with no diagnostics to take: the
    // later rounds of a phased exchange are messages, and both builds send the same ones.
    if (want_diag || s + 3 > measured) solver.complete_exchange();
    step_census = step_census + (mpi_census() - before);
    elapsed += MPI_Wtime() - t0;
    iterations += solver.pressure().report().sweeps;
    std::optional<FlowDiagnostics> d;
    if (want_series) d = record();
    if (want_diag && s + 3 > measured) tail.push_back(d ? *d : solver.diagnostics());
    if (want_progress) {
      if (!d) d = solver.diagnostics();
      if (is_root())
        std::printf("  step %8ld  t=%-10.5g beta=%-10.4g gamma=%-10.4g div_rms=%-10.3g  %.0f s left\n", done, d->time,
                    d->beta, d->gamma, d->div_rms, elapsed / double(s) * double(measured - s));
      std::fflush(stdout);  // a long run's log is read while it runs
    }
    if (s < measured) save_state(false);
  }
  save_state(true);

  const Validation v = kSimulated ? Validation{true, true, {}, true} : validate(tail, c.domain);
  out.valid = v.valid;
  const TimerReport rep = summarize(solver.timers(), elapsed, dec.comm());
  if (is_root()) {
    std::fputs(timing_report_text(rep, measured, double(product(c.domain.cells))).c_str(), stdout);
    const PressureReport& pr = solver.pressure().report();
    if (iterations > 0) std::printf("  pressure solve: %.4g iterations per step (mean)\n", iterations / double(measured));
    if (pr.setup_seconds > 0) std::printf("  pressure set-up: %.4g s, before the measured steps\n", pr.setup_seconds);
    if (checkpoints + snapshots > 0)
      std::printf("  state output: %d checkpoint(s), %d snapshot(s), %.3g s, outside the measured steps\n",
                  checkpoints, snapshots, state_output_s);
    std::printf("%s\n", v.line().c_str());
  }

  // The messages of a step, summed over the ranks: the same in the simulation build
  // (harness/simgrid/README.md), whose exchanges are these.
  long long sent[2] = {step_census.messages, step_census.bytes}, all_sent[2] = {0, 0};
  MPI_Allreduce(sent, all_sent, 2, MPI_LONG_LONG, MPI_SUM, dec.comm());
  const std::string prof = req.profile.empty() ? std::string() : profile_text(solver.state());
  out.record = run_record(c, req, dec, layout, particle_count, rep, tail.empty() ? 0.0 : tail.back().div_rms,
                          v.valid, iterations / double(measured), solver.pressure().report().setup_seconds);
  out.record.mpi_messages_per_step = double(all_sent[0]) / double(measured);
  out.record.mpi_bytes_per_step = double(all_sent[1]) / double(measured);
  write_outputs(req, prof, series, centroid_rows, out.record);
  return out;
}

}  // namespace

RunOutcome run_case(const ChannelCase& c, const std::vector<Particle>& particles, const RunRequest& req) {
  return run_case_with(c, &particles, req);
}

RunOutcome run_case(const ChannelCase& c, const RunRequest& req) { return run_case_with(c, nullptr, req); }

int run_scaling_case(const ChannelCase& c, const std::string& program, const std::string& experiment, long steps,
                     const std::string& csv, bool force_memory, const StateOptions& state) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  check_case(c, ranks, double(steps + 1) * c.solver.dt);
  RunRequest req;
  req.program = program;
  req.experiment = experiment;
  req.total_steps = steps + 1;
  req.csv = csv;
  req.force_memory = force_memory;
  apply_state_options(state, req);
  return run_case(c, req).valid ? 0 : 4;
}

}  // namespace efsi
