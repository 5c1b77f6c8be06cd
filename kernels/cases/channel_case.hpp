#pragma once
// A channel run's set-up in one place for every driver: box, physics, solid (lattice
// particles or a layered slab), pressure method, and the checks that must pass before
// anything is allocated.
#include <memory>
#include <string>

#include "decomposition.hpp"
#include "domain.hpp"
#include "fsi_solver.hpp"
#include "method_registry.hpp"
#include "paper_constants.hpp"
#include "particles.hpp"

namespace efsi {

struct ChannelCase {
  Domain domain;
  SolverConfig solver;
  MethodChoice method = configure_method("acm", {}, std::nullopt);  // set with choose_method
  int particles = 0;    // the first K lattice sites; 0: none
  double slab = 0.0;    // > 0: the layered case, solid for slab < y < Ly - slab
  ParticleSpec particle;
  Int3 forced_dims{0, 0, 0};
  // MethodBuild::timed_planning: off for the bitwise tests and the counted CI gate.
  bool timed_planning = true;
};

// The paper's weak-scaling block on `ranks` ranks side by side in x: `block`^3 cells on
// 3.6^3 per rank, a particle on every lattice site (2 per rank), G = 50; the method, time
// step and halo mode are the caller's.
ChannelCase weak_block_case(int block, int ranks);

// The method and the Crank-Nicolson sweeps it asks for (c.solver.cn_sweeps).
void choose_method(ChannelCase& c, MethodChoice m);

// The run's rank grid on `ranks` ranks: c.forced_dims where the user (or the case: the weak
// block's ranks side by side in x) forces any; else the method's preferred pattern
// (MethodSpec::preferred_rank_grid: the FFT solve keeps x whole) where it fits the grid;
// else choose_dims' free choice.  Throws ConfigError when nothing fits.
Int3 rank_grid(const ChannelCase& c, int ranks);

// Everything that can be checked without allocating a field: decomposition for `ranks`,
// time step under the viscous, elastic and advective limits, particles inside the box,
// apart and two cells from the walls, the slab two cells from the walls. Throws
// ConfigError naming the value and the limit. Returns the particles to place.
// `t_end` bounds the velocity a run from rest can reach (see time_step_limits.hpp).
// Collective over MPI_COMM_WORLD once MPI is up: the particle check (overlaps, walls) runs
// on rank 0 alone and every rank throws its verdict.  The lattice grows with the ranks of a
// weak-scaling run (2 particles a rank): checked on every rank it cost each rank 0.25 s at
// 8192 ranks, and the simulation build 8192 times that.
std::vector<Particle> validate_case(const ChannelCase& c, int ranks, double t_end);
// validate_case's checks alone, and its particles alone (the whole lattice; no MPI).
void check_case(const ChannelCase& c, int ranks, double t_end);
std::vector<Particle> case_particles(const ChannelCase& c);

// Allocates and fills the initial state (solid fraction, rest) on `decomp`.
std::unique_ptr<FsiSolver> build_solver(const ChannelCase& c, const CartDecomposition& decomp,
                                        const std::vector<Particle>& particles);

// Laminar centreline velocity f Ly^2 / (8 mu): the a-priori velocity scale.
double poiseuille_centre_velocity(const ChannelCase& c);

// The blow-up bound every driver uses unless told otherwise: 100 times that velocity (with
// no driving force, 100 times the elastic wave speed sqrt(G / rho)).
double default_velocity_limit(const ChannelCase& c);

}  // namespace efsi
