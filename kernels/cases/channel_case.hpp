#pragma once
// A channel run's set-up in one place for every driver: box, physics, solid (lattice
// particles or a layered slab), pressure method, and the checks that must pass before
// anything is allocated.
#include <memory>
#include <string>

#include "decomposition.hpp"
#include "domain.hpp"
#include "fft_poisson.hpp"
#include "fsi_solver.hpp"
#include "particles.hpp"

namespace efsi {

enum class PressureKind { acm, sor, fft };

// The paper's grid spacing: 64 cells per 3.6, one particle-lattice cell.
inline constexpr double kPaperSpacing = 3.6 / 64;

struct ChannelCase {
  Domain domain;
  SolverConfig solver;
  PressureKind method = PressureKind::acm;
  int sor_sweeps = 0;   // N_S per step for method sor (>= 1 there)
  int particles = 0;    // the first K lattice sites; 0: none
  double slab = 0.0;    // > 0: the layered case, solid for slab < y < Ly - slab
  ParticleSpec particle;
  Int3 forced_dims{0, 0, 0};
  // FFTW_MEASURE times candidate plans, so which plan runs (and its instruction count) can
  // change from run to run; the counted CI gate needs estimate.
  FftPoisson::Planning fft_planning = FftPoisson::Planning::measure;
};

PressureKind parse_method(const std::string& name);  // throws ConfigError
const char* to_string(PressureKind k);

// Everything that can be checked without allocating a field: decomposition for `ranks`,
// time step under the viscous, elastic and advective limits, particles inside the box,
// apart and two cells from the walls, the slab two cells from the walls. Throws
// ConfigError naming the value and the limit. Returns the particles to place.
// `t_end` bounds the velocity a run from rest can reach (see time_step_limits.hpp).
std::vector<Particle> validate_case(const ChannelCase& c, int ranks, double t_end);

// Allocates and fills the initial state (solid fraction, rest) on `decomp`.
std::unique_ptr<FsiSolver> build_solver(const ChannelCase& c, const CartDecomposition& decomp,
                                        const std::vector<Particle>& particles);

// Laminar centreline velocity f Ly^2 / (8 mu): the a-priori velocity scale.
double poiseuille_centre_velocity(const ChannelCase& c);

// The blow-up bound every driver uses unless told otherwise: 100 times that velocity.
double default_velocity_limit(const ChannelCase& c);

}  // namespace efsi
