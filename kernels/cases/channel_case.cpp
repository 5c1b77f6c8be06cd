#include "channel_case.hpp"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "compute_model.hpp"
#include "config_error.hpp"
#include "first_failure.hpp"
#include "time_step_limits.hpp"

namespace efsi {

void choose_method(ChannelCase& c, MethodChoice m) {
  c.solver.cn_sweeps = m.cn_sweeps;
  c.method = std::move(m);
}

ChannelCase weak_block_case(int block, int ranks) {
  ChannelCase c;
  c.domain.cells = {block * ranks, block, block};
  c.domain.length = {paper::kBlockLength * ranks, paper::kBlockLength, paper::kBlockLength};
  c.solver.physics.G = paper::kShearModulus;
  c.particles = static_cast<int>(lattice_site_count(c.domain, c.particle));
  c.forced_dims = {ranks, 1, 1};
  return c;
}

double poiseuille_centre_velocity(const ChannelCase& c) {
  return laminar_centreline_velocity(c.domain, c.solver.physics.mu, c.solver.physics.force);
}

double default_velocity_limit(const ChannelCase& c) {
  // Without a driving force the laminar velocity is zero and would flag round-off as a
  // blow-up: the elastic wave speed is then the scale, or unit velocity with no solid either.
  const Physics& ph = c.solver.physics;
  double scale = std::fabs(poiseuille_centre_velocity(c));
  if (!(scale > 0.0)) scale = std::sqrt(ph.G / ph.rho);
  if (!(scale > 0.0)) scale = 1.0;
  return 100.0 * scale;
}

Int3 rank_grid(const ChannelCase& c, int ranks) {
  const bool forced = c.forced_dims[0] > 0 || c.forced_dims[1] > 0 || c.forced_dims[2] > 0;
  const Int3 preferred = c.method.spec->preferred_rank_grid();
  if (!forced && preferred != Int3{0, 0, 0}) {
    try {
      return choose_dims(ranks, c.domain.cells, kTransportHalo, preferred);
    } catch (const ConfigError&) {  // it does not fit this grid: the free choice below
    }
  }
  return choose_dims(ranks, c.domain.cells, kTransportHalo, c.forced_dims);
}

namespace {

// The case's particles built and checked (check_particles) on rank 0 alone; its
// ConfigError, if any, thrown by every rank.  Built on every rank, the lattice (2 particles
// a rank of a weak-scaling run) would be held by all of them at once across the broadcast:
// 0.9 MB a rank at 8192 ranks, 7.4 GB in the simulation build's one process.
void check_particles_once(const ChannelCase& c) {
  int up = 0;
  MPI_Initialized(&up);
  if (!up) return check_particles(c.domain, case_particles(c), c.particle);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::string failure;
  if (rank == 0) {
    try {
      check_particles(c.domain, case_particles(c), c.particle);
    } catch (const ConfigError& e) {
      failure = e.what();
    }
  }
  const std::string first = first_failure(MPI_COMM_WORLD, failure);
  if (!first.empty()) throw ConfigError(first);
}

}  // namespace

void check_case(const ChannelCase& c, int ranks, double t_end) {
  const Domain& d = c.domain;
  for (int a = 0; a < 3; ++a)
    if (!(d.length[a] > 0))
      throw ConfigError("box length " + std::to_string(d.length[a]) + " must be positive");
  rank_grid(c, ranks);
  c.method.spec->check_grid(d.cells);
  const Physics& ph = c.solver.physics;
  check_time_step(c.solver.dt, d, ph.rho, ph.mu, ph.G, channel_velocity_estimate(d, ph.rho, ph.mu, t_end, std::fabs(ph.force)));
  if (c.solver.cn_sweeps > 0) check_crank_nicolson_step(c.solver.dt, d, ph.rho, ph.mu);

  if (c.slab > 0) {
    if (c.particles > 0) throw ConfigError("--slab and --particles exclude each other");
    const double dy = d.spacing(Y);
    if (c.slab < 2 * dy || c.slab > d.length[Y] / 2 - dy)
      throw ConfigError("slab half-gap " + std::to_string(c.slab) + " must lie between two cells (" +
                        std::to_string(2 * dy) + ") and Ly/2 - one cell (" + std::to_string(d.length[Y] / 2 - dy) +
                        ")");
    return;
  }
  if (c.particles != 0) check_particles_once(c);
}

std::vector<Particle> case_particles(const ChannelCase& c) {
  if (c.slab > 0 || c.particles == 0) return {};
  return lattice_particles(c.domain, c.particles, c.particle);
}

std::vector<Particle> validate_case(const ChannelCase& c, int ranks, double t_end) {
  check_case(c, ranks, t_end);
  return case_particles(c);
}

std::unique_ptr<FsiSolver> build_solver(const ChannelCase& c, const CartDecomposition& decomp,
                                        const std::vector<Particle>& particles) {
  auto pressure = c.method.spec->make(c.method, MethodBuild{c.solver.comm, c.solver.halo, c.timed_planning});
  auto solver = std::make_unique<FsiSolver>(decomp, c.domain, c.solver, std::move(pressure));
  Field& phi = solver->state().phi();
  setup_stage([&] {
    phi.fill(0.0);
    if (c.slab > 0) {
      // Exact fraction of each cell inside slab < y < Ly - slab.
      const double dy = c.domain.spacing(Y), lo = c.slab, hi = c.domain.length[Y] - c.slab;
      const Int3 n = phi.n();
      for (int j = 0; j < n[Y]; ++j) {
        const double y0 = (phi.offset()[Y] + j) * dy, y1 = y0 + dy;
        const double frac = std::max(0.0, std::min(y1, hi) - std::max(y0, lo)) / dy;
        for (int k = 0; k < n[Z]; ++k)
          for (int i = 0; i < n[X]; ++i) phi(i, j, k) = frac;
      }
    } else if (!particles.empty()) {
      fill_solid_fraction(phi, c.domain, particles, c.particle);
    }
  });
  solver->start_from_rest();
  return solver;
}

}  // namespace efsi
