#pragma once
// The solid cut-off (docs/numerics.md, "Solid cut-off"): below a solid fraction phi_c a cell
// holds interface debris, not solid, and keeps no elastic memory.
#include <array>
#include <bit>
#include <cstdint>

#include "constitutive.hpp"
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

// x where `mask` is all ones, y where it is zero: a select GCC vectorises with the square
// root computed unconditionally (a conditional square root is control flow it will not
// if-convert, and the loop stays scalar).
inline double pick(std::uint64_t mask, double x, double y) {
  return std::bit_cast<double>((std::bit_cast<std::uint64_t>(x) & mask) | (std::bit_cast<std::uint64_t>(y) & ~mask));
}

// The reset below at one centre, for the three diagonal components together (one square
// root serves all three) ...
inline void reset_normal_at(const Field& phi, const Field& phi_new, Field& b0, Field& b1, Field& b2, double cutoff,
                            int i, int j, int k) {
  const std::uint64_t debris = solid_debris<Stagger::cell>(phi, cutoff, i, j, k) ? ~std::uint64_t{0} : 0;
  const double unstrained = sqrt_phi(phi_new(i, j, k));
  b0(i, j, k) = pick(debris, unstrained, b0(i, j, k));
  b1(i, j, k) = pick(debris, unstrained, b1(i, j, k));
  b2(i, j, k) = pick(debris, unstrained, b2(i, j, k));
}

// ... and at one point of a shear component.
template <int A, int B>
inline void reset_shear_at(const Field& phi, Field& b, double cutoff, int i, int j, int k) {
  const double old = b(i, j, k);
  b(i, j, k) = solid_debris<tensor_location(A, B)>(phi, cutoff, i, j, k) ? 0.0 : old;
}

// After an update phi -> phi_new, Bt -> B_new: where `phi` (the state the update started
// from, ghosts current) averaged to a component's location is below `cutoff`, that component
// of B_new is reset to the unstrained sqrt(phi_new) I (diagonal) or 0 (shear), so the debris
// carries no deviatoric stress.  On `cells`, extended to the owned top wall face for the
// components staggered in y.  cutoff <= 0 changes nothing.
void reset_solid_debris(const Field& phi, const Field& phi_new, std::array<Field, 6>& B_new, double cutoff,
                        const Box& cells);
// The same for the one shear component b = Bt_AB (A < B) of B_new.
template <int A, int B>
void reset_shear_debris(const Field& phi, Field& b, double cutoff, const Box& cells);

}  // namespace efsi
