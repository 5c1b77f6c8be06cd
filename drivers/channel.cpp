// channel: one run of any configuration of the channel with particles (DESIGN.md
// section 8). Parses, sets up, times and reports; the physics lives in kernels/.
#include <mpi.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>
#include <sstream>

#include "centroids.hpp"
#include "channel_case.hpp"
#include "config_error.hpp"
#include "driver_support.hpp"
#include "run_record.hpp"
#include "runtime.hpp"
#include "sor_calibration.hpp"

using namespace efsi;

namespace {

struct Options {
  std::string cells = "64", length, method = "acm", comm = "sync", decomp;
  std::optional<double> eps, t_end, slab, velocity_limit;
  std::optional<int> ns, nc, particles;
  double dt = 1.25e-5, G = 50.0, force = 1.0;
  long steps = 50;
  int every = 10, threads = 0, progress = 0;
  std::string profile, series, centroids, csv;
  bool calibrate = false;
  int max_sweeps = 20000;
};

// Collective. Checks without creating anything: the directory must exist and be
// writable, and an existing file must be writable; rank 0 looks, every rank throws.
void check_writable(const std::string& path, const char* option) {
  if (path.empty()) return;
  int ok = 1;
  if (is_root()) {
    const auto slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : (slash == 0 ? "/" : path.substr(0, slash));
    ok = ::access(dir.c_str(), W_OK) == 0 && (::access(path.c_str(), F_OK) != 0 || ::access(path.c_str(), W_OK) == 0);
  }
  MPI_Bcast(&ok, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (!ok) throw ConfigError(std::string(option) + " '" + path + "' cannot be written");
}

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

void write_file(const std::string& path, const std::string& text) {
  std::ofstream f(path, std::ios::trunc);
  f << text;
  if (!f) throw std::runtime_error("cannot write " + path);
}

std::string format_eps(double eps) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", eps);
  return b;
}

// --calibrate: the paper's N_S count on a developed state (sor_calibration.hpp), one rank.
int calibrate(const Options& o, const ChannelCase& c, const std::vector<Particle>& particles) {
  check_writable(o.series, "--series");
  CartDecomposition dec(MPI_COMM_WORLD, c.domain.cells, kTransportHalo, c.forced_dims);
  const std::vector<double> eps = o.eps ? std::vector<double>{*o.eps} : std::vector<double>{1e-3, 1e-4};
  std::printf("calibrate: %s cells, box %.4g x %.4g x %.4g, %zu particles, G=%g, dt=%g, N_C=%d\n"
              "  state: laminar Poiseuille flow with the particles at rest and unstrained, then %ld steps of the "
              "FFT reference; rhs = D*/dt of the next step, SOR (omega 1.6) from dp = 0\n",
              to_string(c.domain.cells).c_str(), c.domain.length[0], c.domain.length[1], c.domain.length[2],
              particles.size(), c.solver.physics.G, c.solver.dt, c.solver.cn_sweeps, o.steps);
  const SorCalibration cal = calibrate_sor(c, dec, particles, o.steps, eps, o.max_sweeps);
  std::printf("  initial RMS residual %.6g; after %zu sweeps %.3g of it, max |dp_sor - dp_fft| = %.3g of max |dp_fft|\n",
              cal.initial_residual, cal.history.size(), cal.history.empty() ? 1.0 : cal.history.back(),
              cal.fft_difference);
  bool reached = true;
  for (std::size_t e = 0; e < eps.size(); ++e) {
    if (cal.sweeps[e] < 0) {
      std::printf("  eps %g: not reached in --max-sweeps %d\n", eps[e], o.max_sweeps);
      reached = false;
    } else {
      std::printf("  eps %g: N_S = %d\n", eps[e], cal.sweeps[e]);
    }
  }
  if (!o.series.empty()) {
    std::ostringstream t;
    t << "sweep,relative_residual\n";
    for (std::size_t m = 0; m < cal.history.size(); ++m) t << m + 1 << ',' << cal.history[m] << '\n';
    write_file(o.series, t.str());
  }
  return reached ? 0 : 4;
}

int run(const Options& o) {
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  set_threads(o.threads);

  ChannelCase c;
  c.domain.cells = parse_int3(o.cells, "--cells");
  if (o.length.empty()) {
    // The paper's spacing: 64 cells per 3.6.
    for (int a = 0; a < 3; ++a) c.domain.length[a] = c.domain.cells[a] * (3.6 / 64);
  } else {
    c.domain.length = parse_double3(o.length, "--length");
  }
  c.method = parse_method(o.method);
  if (o.comm == "sync") c.solver.comm = CommMode::sync;
  else if (o.comm == "async") c.solver.comm = CommMode::async;
  else throw ConfigError("unknown --comm '" + o.comm + "': expected sync or async");
  if (c.method != PressureKind::sor) {
    if (o.eps) throw ConfigError("--eps applies to --method sor only");
    if (o.ns) throw ConfigError("--ns applies to --method sor only");
    if (o.calibrate) throw ConfigError("--calibrate applies to --method sor only");
  }
  if (o.eps && !(*o.eps > 0 && *o.eps < 1))
    throw ConfigError("--eps " + std::to_string(*o.eps) + " must lie in (0, 1)");
  if (o.ns && *o.ns < 1) throw ConfigError("--ns " + std::to_string(*o.ns) + " must be at least 1");
  if (o.nc && *o.nc < 0) throw ConfigError("--nc " + std::to_string(*o.nc) + " must be 0 (explicit stress) or more");
  if (o.max_sweeps < 1) throw ConfigError("--max-sweeps " + std::to_string(o.max_sweeps) + " must be at least 1");
  // The paper's SOR path treats the stress by Crank-Nicolson with N_C = 20; ACM and the
  // FFT reference are explicit unless --nc asks otherwise.
  c.solver.cn_sweeps = o.nc.value_or(c.method == PressureKind::sor ? 20 : 0);
  if (c.method == PressureKind::sor && !o.calibrate)
    c.sor_sweeps = o.ns ? *o.ns : calibrated_sor_sweeps(o.eps.value_or(1e-3));
  else if (c.method == PressureKind::sor)
    c.sor_sweeps = 1;  // unused: the calibration counts them
  c.solver.dt = o.dt;
  if (!std::isfinite(o.G) || o.G < 0) throw ConfigError("--G " + std::to_string(o.G) + " must be zero or positive");
  if (!std::isfinite(o.force)) throw ConfigError("--force must be a finite number");
  c.solver.physics.G = o.G;
  c.solver.physics.force = o.force;
  if (o.threads < 0) throw ConfigError("--threads " + std::to_string(o.threads) + " must be positive (0: OMP_NUM_THREADS)");
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
  c.solver.velocity_limit = o.velocity_limit.value_or(100.0 * std::fabs(poiseuille_centre_velocity(c)));

  long total = o.steps + 1;  // one warm-up step, then the measured ones
  if (o.t_end) {
    total = std::lround(*o.t_end / o.dt);
    if (total < 2) throw ConfigError("--t-end " + std::to_string(*o.t_end) + " is under two steps of dt");
  } else if (o.steps < 1) {
    throw ConfigError("--steps " + std::to_string(o.steps) + " must be at least 1");
  }
  const long measured = total - 1;

  const std::vector<Particle> particles = validate_case(c, ranks, double(total) * o.dt);
  if (o.calibrate) {
    if (ranks != 1) throw ConfigError("--calibrate runs on one rank (the paper's procedure); started on " +
                                      std::to_string(ranks));
    return calibrate(o, c, particles);
  }
  for (const auto& [path, opt] : {std::pair{o.profile, "--profile"}, {o.series, "--series"},
                                  {o.centroids, "--centroids"}, {o.csv, "--csv"}})
    check_writable(path, opt);

  CartDecomposition dec(MPI_COMM_WORLD, c.domain.cells, kTransportHalo, c.forced_dims);
  const bool over = node_oversubscribed(dec.comm(), max_threads());
  if (is_root()) {
    std::printf("channel: %s, %s halo, %d ranks as %s, local block %s, %d thread(s) per rank%s\n",
                to_string(c.method), to_string(c.solver.comm), ranks, to_string(dec.dims()).c_str(),
                to_string(dec.local()).c_str(), max_threads(), over ? " (oversubscribed: timings not valid)" : "");
    std::printf("         %s cells, box %.4g x %.4g x %.4g, %zu particles%s, G=%g, dt=%g, %ld steps + 1 warm-up\n",
                to_string(c.domain.cells).c_str(), c.domain.length[0], c.domain.length[1], c.domain.length[2],
                particles.size(), c.slab > 0 ? " (layered slab)" : "", o.G, o.dt, measured);
  }
  auto solver = build_solver(c, dec, particles);

  std::string series = series_header(), centroid_rows = "step,time,region,volume,x,y,z\n";
  auto record = [&]() {
    const FlowDiagnostics d = solver->diagnostics();
    if (!o.series.empty()) series += series_row(d);
    if (!o.centroids.empty()) {
      const std::vector<SolidRegion> regions = solid_regions(solver->state().phi(), c.domain, dec);
      char b[200];
      for (std::size_t r = 0; r < regions.size(); ++r) {
        std::snprintf(b, sizeof b, "%ld,%.9g,%zu,%.9g,%.9g,%.9g,%.9g\n", d.step, d.time, r, regions[r].volume,
                      regions[r].centroid[0], regions[r].centroid[1], regions[r].centroid[2]);
        centroid_rows += b;
      }
    }
    return d;
  };
  if (!o.series.empty() || !o.centroids.empty()) record();

  solver->step();  // warm-up: first touch of the work arrays, MPI connections
  if ((!o.series.empty() || !o.centroids.empty()) && o.every == 1) record();
  solver->timers().reset();
  const int progress = o.progress > 0 ? o.progress : (total >= 200 ? int(total / 20) : 0);

  double elapsed = 0.0;
  std::vector<FlowDiagnostics> tail;  // the last three steps, for the energy-budget check
  for (long s = 1; s <= measured; ++s) {
    const long done = s + 1;  // the warm-up step came first
    const bool want_series = (!o.series.empty() || !o.centroids.empty()) && done % o.every == 0;
    const bool want_progress = progress > 0 && done % progress == 0;
    const bool want_diag = want_series || want_progress || s + 3 > measured;
    const double t0 = MPI_Wtime();
    solver->step();
    // Diagnostics need current ghosts: an async exchange is completed inside the timed
    // step, so that every region the timers count lies within the measured time.
    if (want_diag) solver->complete_exchange();
    elapsed += MPI_Wtime() - t0;
    std::optional<FlowDiagnostics> d;
    if (want_series) d = record();
    if (s + 3 > measured) tail.push_back(d ? *d : solver->diagnostics());
    if (want_progress) {
      if (!d) d = solver->diagnostics();
      if (is_root())
        std::printf("  step %8ld  t=%-10.5g beta=%-10.4g gamma=%-10.4g div_rms=%-10.3g  %.0f s left\n", done, d->time,
                    d->beta, d->gamma, d->div_rms, elapsed / double(s) * double(measured - s));
    }
  }

  // Validation: finite, divergence small against the velocity gradients, energy budget.
  const FlowDiagnostics& last = tail.back();
  bool valid = std::isfinite(last.kinetic) && std::isfinite(last.div_rms) && std::isfinite(last.u_max);
  const double dx = std::min({c.domain.spacing(X), c.domain.spacing(Y), c.domain.spacing(Z)});
  const double div_scale = std::max(last.u_max, 1e-300) / dx;
  const bool div_ok = last.div_max < 1e-2 * div_scale;
  double budget = 0.0;
  if (tail.size() >= 3) {
    const auto& a = tail[tail.size() - 3];
    const auto& m = tail[tail.size() - 2];
    const auto& b = tail.back();
    const double dkdt = (b.kinetic - a.kinetic) / (b.time - a.time);
    const double largest = std::max({std::fabs(dkdt), std::fabs(m.input), std::fabs(m.eps_solid), std::fabs(m.eps_fluid)});
    budget = largest > 0 ? std::fabs(-dkdt + m.input - m.eps_solid - m.eps_fluid) / largest : 0.0;
  }
  const bool budget_ok = budget < 0.02;
  valid = valid && div_ok && budget_ok;

  const TimerReport rep = summarize(solver->timers(), elapsed, dec.comm());
  if (is_root()) {
    std::printf("timing over %ld steps (slowest rank %.4g s, %.4g s/step, %.3g Mcell updates/s):\n", measured,
                rep.elapsed.max, rep.elapsed.max / double(measured),
                double(product(c.domain.cells)) * double(measured) / rep.elapsed.max / 1e6);
    std::printf("  %-12s %12s %12s %12s\n", "region", "min s", "mean s", "max s");
    for (int r = 0; r < kRegionCount; ++r) {
      const Spread& sp = rep.region[r];
      if (sp.max == 0) continue;
      std::printf("  %-12s %12.5g %12.5g %12.5g\n", std::string(to_string(static_cast<Region>(r))).c_str(), sp.min,
                  sp.mean, sp.max);
    }
    std::printf("  comm fraction %.4f (mean halo MPI + reductions + transposes / slowest elapsed)\n", rep.comm_fraction);
    std::printf("validation: div_max*dx/U_max = %.3g (limit 1e-2), energy budget residual %.3g of its largest "
                "term (limit 0.02): %s\n",
                last.div_max / div_scale, budget, valid ? "SUCCESSFUL" : "FAILED");
  }

  const std::string prof = o.profile.empty() ? std::string() : profile_text(solver->state());
  if (is_root()) {
    if (!o.profile.empty()) write_file(o.profile, prof);
    if (!o.series.empty()) write_file(o.series, series);
    if (!o.centroids.empty()) write_file(o.centroids, centroid_rows);
    if (!o.csv.empty()) {
      RunRecord r;
      r.experiment = c.slab > 0 ? "layered" : "channel";
      r.method = to_string(c.method);
      r.comm = to_string(c.solver.comm);
      r.ranks = ranks;
      r.threads = max_threads();
      r.px = dec.dims()[0], r.py = dec.dims()[1], r.pz = dec.dims()[2];
      r.nx = c.domain.cells[0], r.ny = c.domain.cells[1], r.nz = c.domain.cells[2];
      r.particles = static_cast<long>(particles.size());
      r.steps = measured;
      r.dt = c.solver.dt;
      if (c.method == PressureKind::sor) {
        r.ns_per_step = std::to_string(c.sor_sweeps);
        if (!o.ns || o.eps) r.eps = format_eps(o.eps.value_or(1e-3));
      }
      if (c.solver.cn_sweeps > 0) r.nc_per_step = std::to_string(c.solver.cn_sweeps);
      r.timing = rep;
      r.div_rms = last.div_rms;
      r.valid = valid && !over;
      r.oversubscribed = over;
      append_csv(o.csv, r);
    }
  }
  return valid ? 0 : 4;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{"One run of the explicit full-Eulerian FSI channel (DESIGN.md section 8).\n"
               "One warm-up step precedes the measured --steps; --t-end counts every step.",
               "channel"};
  app.add_option("--cells", o.cells, "N or NX,NY,NZ cells")->capture_default_str();
  app.add_option("--length", o.length, "L or LX,LY,LZ box lengths (default: 3.6/64 per cell)");
  app.add_option("--method", o.method, "pressure method: acm | sor | fft")->capture_default_str();
  app.add_option("--comm", o.comm, "halo mode: sync | async")->capture_default_str();
  app.add_option("--eps", o.eps,
                 "SOR residual ratio: picks the calibrated N_S (1e-3 or 1e-4; default 1e-3), or the target of "
                 "--calibrate (sor only)");
  app.add_option("--ns", o.ns, "SOR sweeps per step N_S (sor only; overrides --eps)");
  app.add_option("--nc", o.nc, "Crank-Nicolson stress sweeps per step N_C (0: explicit Euler; default 20 for sor, 0 "
                 "otherwise)");
  app.add_flag("--calibrate", o.calibrate,
               "sor, one rank: count the sweeps to reach --eps (default: 1e-3 and 1e-4) on a developed state "
               "(--steps FFT steps from laminar flow) and exit; --series writes the residual history");
  app.add_option("--max-sweeps", o.max_sweeps, "--calibrate gives up after this many sweeps")->capture_default_str();
  app.add_option("--dt", o.dt, "time step")->capture_default_str();
  auto* steps = app.add_option("--steps", o.steps, "measured steps")->capture_default_str();
  app.add_option("--t-end", o.t_end, "run to this time instead of --steps")->excludes(steps);
  app.add_option("--G", o.G, "shear modulus")->capture_default_str();
  app.add_option("--force", o.force, "driving pressure gradient along x")->capture_default_str();
  app.add_option("--particles", o.particles,
                 "first K lattice sites (0: none; default: all sites when the box is whole 3.6 lattice cells)");
  app.add_option("--slab", o.slab, "layered case: solid for A < y < Ly - A");
  app.add_option("--decomp", o.decomp, "force PX,PY,PZ ranks (0 entries free)");
  app.add_option("--threads", o.threads, "OpenMP threads per rank (default: OMP_NUM_THREADS)");
  app.add_option("--profile", o.profile, "write x-z means against y at the end: y,u,phi,Bt11,Bt12");
  app.add_option("--series", o.series, "write diagnostics every --every steps");
  app.add_option("--centroids", o.centroids, "write particle centroids every --every steps");
  app.add_option("--every", o.every, "steps between series rows")->capture_default_str();
  app.add_option("--csv", o.csv, "append the run's result row to this CSV file");
  app.add_option("--progress", o.progress, "print progress every N steps (default: 20 times in long runs)");
  app.add_option("--velocity-limit", o.velocity_limit, "blow-up bound (default: 100 x laminar centre velocity)");
  return run_driver(argc, argv, app, [&] { return run(o); });
}
