#pragma once
// Shared set-up for the solver tests: a channel on a given decomposition, analytic
// solutions, and gathering a distributed field onto one rank for comparisons.
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "acm.hpp"
#include "decomposition.hpp"
#include "field_gather.hpp"
#include "fsi_solver.hpp"
#include "particles.hpp"

namespace efsi::testing {

struct Channel {
  std::unique_ptr<CartDecomposition> decomp;
  std::unique_ptr<FsiSolver> solver;
};

// `particles` lattice sites of the box (0: none) as the solid, via the kernels' own
// placement and sampling; the rest of the state at rest. `pressure`: ACM when null.
inline Channel make_channel(MPI_Comm comm, const Domain& dom, const Int3& dims, const SolverConfig& cfg,
                            int particles = 0, std::unique_ptr<PressureMethod> pressure = nullptr) {
  Channel c;
  c.decomp = std::make_unique<CartDecomposition>(comm, dom.cells, kTransportHalo, dims);
  if (!pressure) pressure = std::make_unique<AcmPressure>();
  c.solver = std::make_unique<FsiSolver>(*c.decomp, dom, cfg, std::move(pressure));
  Field& phi = c.solver->state().phi();
  phi.fill(0.0);
  if (particles != 0) fill_solid_fraction(phi, dom, lattice_particles(dom, particles), ParticleSpec{});
  c.solver->start_from_rest();
  return c;
}

// The paper's weak-scaling block, 3.6^3 with its 2 particles, at n^3 cells.
inline Domain paper_block(int n) { return Domain{{n, n, n}, {3.6, 3.6, 3.6}}; }

// Start-up Poiseuille flow between walls at y = 0 and y = h (docs/numerics.md, "Validation cases").
inline double poiseuille_startup(double y, double t, double h, double f, double mu, double rho) {
  double u = f / (2 * mu) * y * (h - y);
  const double pi = std::acos(-1.0);
  for (int n = 1; n < 400; n += 2) {
    const double decay = std::exp(-n * n * pi * pi * mu * t / (rho * h * h));
    if (decay < 1e-300) break;
    u -= 4 * f * h * h / (mu * pi * pi * pi * n * n * n) * std::sin(n * pi * y / h) * decay;
  }
  return u;
}

// x-z means of a field's owned points against global j, summed over ranks (every rank
// gets the whole profile).
inline std::vector<double> xz_mean_profile(const Field& f, const Domain& dom, MPI_Comm comm) {
  std::vector<double> local(dom.cells[Y], 0.0), global(dom.cells[Y], 0.0);
  const Int3 n = f.n();
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) local[f.offset()[Y] + j] += f(i, j, k);
  MPI_Allreduce(local.data(), global.data(), dom.cells[Y], MPI_DOUBLE, MPI_SUM, comm);
  for (double& v : global) v /= double(dom.cells[X]) * dom.cells[Z];
  return global;
}

// Start-up Poiseuille flow between walls at y = 0 and 1 on ny cells (6 x ny x 6, rho = mu =
// f = 1), dt = 0.1 dy^2 (dt ~ dy^2 keeps the Euler error at second order in dy too), to
// t = 0.05: the max error of the x-z mean of u against the series solution. `cfg` gives
// everything but dt; `pressure`: ACM when null.
inline double startup_poiseuille_error(int ny, SolverConfig cfg, std::unique_ptr<PressureMethod> pressure = nullptr) {
  const double dy = 1.0 / ny;
  const Domain dom{{6, ny, 6}, {6 * dy, 1.0, 6 * dy}};
  cfg.dt = 0.1 * dy * dy;
  Channel c = make_channel(MPI_COMM_WORLD, dom, {0, 0, 0}, cfg, 0, std::move(pressure));
  const long steps = std::lround(0.05 / cfg.dt);
  for (long s = 0; s < steps; ++s) c.solver->step();
  c.solver->complete_exchange();
  const auto prof = xz_mean_profile(c.solver->state().vel(X), dom, c.decomp->comm());
  double err = 0;
  for (int j = 0; j < ny; ++j)
    err = std::max(err, std::fabs(prof[j] - poiseuille_startup((j + 0.5) * dy, c.solver->time(), 1.0, 1.0, 1.0, 1.0)));
  return err;
}

using efsi::gather_global;

}  // namespace efsi::testing
