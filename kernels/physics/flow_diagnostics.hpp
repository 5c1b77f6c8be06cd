#pragma once
// The kinetic-energy budget and the flow's state (docs/numerics.md, "diagnostics").
#include "fsi_state.hpp"

namespace efsi {

// Means <.> are volume means over the box.
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

// Of the current state (ghosts must be current). Collective.  The pressure method's
// fields (beta, gamma) and the Mach figures are the solver's to fill.
FlowDiagnostics flow_diagnostics(const FsiState& s, const Physics& ph);

}  // namespace efsi
