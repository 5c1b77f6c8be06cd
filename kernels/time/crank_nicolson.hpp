#pragma once
// Crank-Nicolson deviatoric stress by fixed-point sweeps (docs/numerics.md, "SMAC"): div tau in v*
// becomes (div tau(v^N, Bt^N) + div tau(v*, Bt*)) / 2, where Bt* is Bt carried by v^N
// (the transport's WENO5 advection) but stretched by the velocity gradient of the
// current iterate v*:
//   Bt* = Bt^N - dt v^N.grad Bt^N + dt (L*.Bt^N + Bt^N.L*^T),  L* = grad v*.
// The solid fraction in tau(v*, Bt*) is phi^N (the stress is then linear in (v*, Bt*),
// and the iteration needs no phi exchange).  Each sweep:
//   exchange v* (26 directions: the stretching averages gradients over edges),
//   Bt* and tau* on the owned points, exchange tau* (6 faces),
//   v* = v*_explicit + dt/(2 rho) (div tau* - div tau^N) on the owned faces.
// That is the paper's 9 exchanged quantities per sweep (3 velocities, 6 stresses).  A sweep
// multiplies the error by up to 12 dt mu / (rho h^2) (time_step_limits.hpp refuses dt
// where that exceeds 1/2); at the paper's SOR step it is 0.24, and N_C = 20 takes the
// change of the last sweep to round-off (tests/test_smac_solver.cpp).
#include <array>

#include "fsi_equations.hpp"
#include "halo_exchange.hpp"
#include "region_timers.hpp"

namespace efsi {

class CrankNicolsonStress {
 public:
  // work.vstar is the iterate; its exchanges are built here once. sweeps: N_C >= 1.
  // `v_reach`: how the v* exchange, which fills every ghost, reaches the corners.
  CrankNicolsonStress(const CartDecomposition& decomp, FsiWork& work, int sweeps, RegionTimers* timers,
                      Reach v_reach = Reach::full);
  CrankNicolsonStress(const CrankNicolsonStress&) = delete;
  CrankNicolsonStress& operator=(const CrankNicolsonStress&) = delete;

  // On entry: work.tau = tau(v^N, Bt^N) wherever div reads it, work.vstar = the explicit v*
  // on the owned faces, work.B_new = the explicitly transported Bt on the owned points,
  // s = the state at step N with current ghosts.  On exit work.vstar holds the iterate
  // after N_C sweeps with every ghost (26 directions) current.
  void iterate(const FsiState& s, FsiWork& work, const Physics& ph, double dt);

  int sweeps() const { return sweeps_; }
  // max |change of v*| on this rank in the last sweep (for convergence checks).
  double last_change() const { return last_change_; }

 private:
  int sweeps_;
  RegionTimers* timers_;
  std::array<Field, 3> v_explicit_, v_previous_;  // v* - c div tau^N; the last sweep's iterate
  std::array<Field, 6> b_advected_, tau_star_;
  HaloExchange v_halo_, tau_halo_;
  double last_change_ = 0.0;
};

}  // namespace efsi
