#pragma once
// The only part that differs between the three methods (docs/numerics.md, "The pressure methods"): the
// pressure increment dp with D^{N+1} = D* - dt Lap(dp), D* = rho div v*.
#include "fsi_equations.hpp"
#include "region_timers.hpp"

namespace efsi {

// What the pressure correction of the last step chose (ACM: beta, gamma).
struct PressureReport {
  double beta = 0, gamma = 0;
  int sweeps = 0;          // iterations of the last solve: SOR sweeps, multigrid V-cycles
  double setup_seconds = 0;  // the method's one-time set-up in attach (hypre's, FFTW's plans)
  double residual = 0;     // relative residual of the last solve (SMAC)
};

struct PressureInputs {
  const FsiState& state;  // p^N with its ghosts
  FsiWork& work;          // work.div holds D* on owned cells and face ghosts
  const Physics& physics;
  double dt;
  RegionTimers& timers;
};

class PressureMethod {
 public:
  virtual ~PressureMethod() = default;
  // Called once by the solver that owns `work`, before the first increment: a method
  // that keeps plans or exchanges bound to the work arrays builds them here. Collective.
  virtual void attach(const CartDecomposition& /*decomp*/, const Domain& /*domain*/, FsiWork& /*work*/,
                      RegionTimers& /*timers*/) {}
  // Fills work.dp on the owned cells and their face ghosts, shifted so that the new
  // pressure p^N + dp keeps whatever mean the method fixes. Collective.
  virtual void increment(PressureInputs& in) = 0;
  virtual const PressureReport& report() const = 0;
};

}  // namespace efsi
