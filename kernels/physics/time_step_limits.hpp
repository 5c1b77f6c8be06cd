#pragma once
// Explicit stability limits of the scheme (docs/numerics.md, "Time-step limits": explicit Euler; second-order central
// differences on the staggered grid for momentum, viscosity and elasticity; WENO5 transport
// of phi and Bt), checked before a run allocates anything (docs/architecture.md, "Programs and their command lines").
//
// Each limit is the von Neumann bound of explicit Euler on the linearised equations, with a
// safety factor only where the linear analysis is known to be optimistic:
//   viscous    rho / (2 mu (1/dx^2 + 1/dy^2 + 1/dz^2))  = h^2 rho / (6 mu) for cubic cells.
//              Exact for Euler with the 7-point Laplacian (the highest mode decays by -1 per
//              step at the bound). 2 mu div D is mu lap v only while div v = 0; the pressure
//              keeps it so (projection) or near it (ACM).
//   elastic    0.5 mu / G. A Kelvin-Voigt solid (tau = 2 mu D + G strain) has the modes
//              lambda^2 + nu K^2 lambda + c^2 K^2 = 0, c^2 = G / rho. Underdamped ones
//              (nu K < 2 c; always the long waves) need dt |lambda|^2 <= 2 |Re lambda|, i.e.
//              dt <= nu / c^2 = mu / G for every K: Euler alone amplifies an undamped wave at
//              any CFL, viscosity is what holds it, so the usual wave CFL h / c is not this
//              scheme's limit. It is implied anyway: 0.5 h / c is above min(viscous, elastic)
//              for every h, c. Overdamped modes are bounded by the viscous limit. The factor
//              0.5 covers the stiffening of a stretched neo-Hookean solid (c^2 ~ G lambda^2).
//              Checked in 1-D: G = 2000, h = 0.05625 decays at dt = 0.95 mu/G and grows to
//              1e137 in 20000 steps at 1.05 mu/G, where 0.5 h / c would still allow it.
//   advective  min(0.1 h / U, 2 mu / (rho U^2)), h the smallest spacing.
//              2 mu / (rho U^2): central momentum advection with Euler is stable only with
//              enough viscosity (exact for Euler + central differences, cell-Reynolds form).
//              0.1 h / U: Euler + WENO5 transport of phi and Bt has no stable CFL at all in
//              the linear sense (|1 - i CFL theta| > 1 on resolved waves; only the nonlinear
//              weights' dissipation at fronts holds it). In 1-D transport over 40000 steps a
//              step front stays bounded (overshoot 0.04) at CFL 0.06, the paper's accuracy
//              case, reaches 0.9 at 0.1 and blows up within 4400 steps at 0.2; 0.1 is
//              where the paper's runs (CFL 0.02 to 0.06) keep a margin and worse is refused.
#include "domain.hpp"

namespace efsi {

// Largest stable dt per mechanism; +infinity where the mechanism is absent (G = 0, U = 0).
struct TimeStepLimits {
  double viscous, elastic, advective;
  double smallest() const;
};

inline constexpr double kElasticSafety = 0.5;  // of mu / G
inline constexpr double kAdvectiveCfl = 0.1;   // of h / U

TimeStepLimits time_step_limits(const Domain& domain, double rho, double mu, double G, double u_estimate);

// Throws ConfigError naming dt, the tightest limit it exceeds, its formula and value, e.g.
// "dt=0.01 exceeds the viscous limit h^2 rho/(6 mu) = 5.273e-04 (h=0.05625, rho=1, mu=1)".
// Also throws for non-physical input (dt, rho, mu not positive; G, u_estimate negative).
void check_time_step(double dt, const Domain& domain, double rho, double mu, double G, double u_estimate);

// The Crank-Nicolson stress iteration (crank_nicolson.hpp) is a fixed point whose sweep
// multiplies the error by up to dt mu lambda_max / (2 rho), lambda_max = 8 (1/dx^2 + 1/dy^2
// + 1/dz^2) (the Laplacian's 4 per axis, doubled by grad div for compressive modes).
// Throws ConfigError unless a sweep at least halves it: dt <= rho / (8 mu sum 1/h^2),
// h^2 rho / (24 mu) for cubic cells, a quarter of the explicit viscous limit.
double crank_nicolson_limit(const Domain& domain, double rho, double mu);
void check_crank_nicolson_step(double dt, const Domain& domain, double rho, double mu);

// Centreline velocity of laminar Poiseuille flow between the walls y = 0 and y = L_y driven
// by the body force f: f L_y^2 / (8 mu), the largest velocity the developed channel reaches.
double laminar_centreline_velocity(const Domain& domain, double mu, double f = 1.0);

// A-priori velocity estimate for a run started from rest and ended at t_end:
// min(laminar centreline, f t_end / rho). The second bound holds for the particle-free
// start-up (the maximum principle on u_t = nu u_yy + f / rho) and keeps the short scaling
// runs, which never come near the developed flow, from being judged by it.
double channel_velocity_estimate(const Domain& domain, double rho, double mu, double t_end, double f = 1.0);

}  // namespace efsi
