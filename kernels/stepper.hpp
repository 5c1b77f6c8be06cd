#pragma once
// The interface every pressure method presents to drivers, tests and benchmarks:
// advance one step, report diagnostics.
#include <stdexcept>
#include <string>

#include "region_timers.hpp"

namespace efsi {

// What the pressure correction of the last step chose (ACM: beta, gamma).
struct PressureReport {
  double beta = 0, gamma = 0;
  int sweeps = 0;          // SOR sweeps of the last step
  double residual = 0;     // relative residual of the last solve (SMAC)
};

// DESIGN.md section 6: means <.> are volume means over the box.
struct FlowDiagnostics {
  long step = 0;
  double time = 0;
  double kinetic = 0;       // K = <rho v.v / 2>
  double input = 0;         // I = <f u>
  double eps_solid = 0;     // <G sqrt(phi) Bt' : D>
  double eps_fluid = 0;     // <2 mu D : D>
  double div_rms = 0, div_max = 0;
  double u_max = 0;         // largest |velocity component| on any face
  double flow_rate = 0;     // volume flux through a y-z cross-section
  double solid_fraction = 0;  // <phi>, conserved
  double beta = 0, gamma = 0;
  double mach = 0, mach_bound = 0;  // U_max / beta and 2 sqrt(3 eta), eta = U_max dt / dx
};

class Stepper {
 public:
  virtual ~Stepper() = default;
  virtual void step() = 0;
  // Collective. Completes any exchange in flight first.
  virtual FlowDiagnostics diagnostics() = 0;
  virtual long steps_done() const = 0;
  virtual double time() const = 0;
  virtual const RegionTimers& timers() const = 0;
  virtual RegionTimers& timers() = 0;
};

// A run that blew up: non-finite values or velocities past the bound. Thrown on every
// rank at the same step; what() names the step, the quantity and where.
class BlowUp : public std::runtime_error {
 public:
  explicit BlowUp(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace efsi
