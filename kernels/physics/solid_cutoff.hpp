#pragma once
// The solid cut-off (docs/numerics.md, "Solid cut-off"): below a solid fraction phi_c a cell
// holds interface debris, not solid, and keeps no elastic memory.
#include <array>

#include "fsi_state.hpp"
#include "stencils.hpp"

namespace efsi {

// The cut-off's test for a Bt component at location T: `phi` (the state an update started
// from) averaged to (i, j, k) of T is below `cutoff`.  One definition: reset_solid_debris
// resets where it holds, and the transport skips only what it resets.
template <Stagger T>
inline bool solid_debris(const Field& phi, double cutoff, int i, int j, int k) {
  return average<Stagger::cell, T>(phi, i, j, k) < cutoff;
}

// After an update phi -> phi_new, Bt -> B_new: where `phi` (the state the update started
// from, ghosts current) averaged to a component's location is below `cutoff`, that component
// of B_new is reset to the unstrained sqrt(phi_new) I (diagonal) or 0 (shear), so the debris
// carries no deviatoric stress.  On `cells`, extended to the owned top wall face for the
// components staggered in y.  cutoff <= 0 changes nothing.
void reset_solid_debris(const Field& phi, const Field& phi_new, std::array<Field, 6>& B_new, double cutoff,
                        const Box& cells);

}  // namespace efsi
