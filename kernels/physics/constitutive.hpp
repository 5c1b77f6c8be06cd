#pragma once
// Strain rate and the solid's deviatoric stress on the staggered grid: the one
// definition that the momentum equation and the energy-budget diagnostics share.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "fsi_state.hpp"
#include "stencils.hpp"

namespace efsi {

struct InverseSpacing {
  double h[3];
  explicit InverseSpacing(const Domain& d) : h{1.0 / d.spacing(X), 1.0 / d.spacing(Y), 1.0 / d.spacing(Z)} {}
};

// WENO transport can undershoot phi slightly below zero at the interface: sqrt of
// std::max(phi, 0.0).  The clamp is a bit mask, since GCC turns a select before sqrt into
// a branch around it, which keeps the loops that call this scalar.
inline double sqrt_phi(double phi) {
  const std::uint64_t keep = phi < 0.0 ? 0 : ~std::uint64_t{0};
  return std::sqrt(std::bit_cast<double>(std::bit_cast<std::uint64_t>(phi) & keep));
}

// L_AM = d v_A / d x_M at its own location, tensor_location(A, M).
template <int A, int M>
inline double grad_v(const FieldSet& s, const InverseSpacing& inv, int i, int j, int k) {
  return difference<face_location(A), M>(s.vel(A), i, j, k, inv.h[M]);
}

// L_AM averaged to location T: the average of the raw differences, times h^-1 once (where
// averaging the gradients would multiply each sample).
template <int A, int M, Stagger T>
inline double grad_v_at(const FieldSet& s, const InverseSpacing& inv, int i, int j, int k) {
  const Field& v = s.vel(A);
  return average<gradient_location(A, M), T>(
             [&v](int x, int y, int z) { return difference<face_location(A), M>(v, x, y, z, 1.0); }, i, j, k) *
         inv.h[M];
}

// D_AB at tensor_location(A, B).
template <int A, int B>
inline double strain_rate(const FieldSet& s, const InverseSpacing& inv, int i, int j, int k) {
  if constexpr (A == B) return grad_v<A, A>(s, inv, i, j, k);
  else return 0.5 * (grad_v<A, B>(s, inv, i, j, k) + grad_v<B, A>(s, inv, i, j, k));
}

// sqrt(phi) (Bt - tr(Bt)/3 I)_AA at a centre from its sqrt(phi), Bt_AA and diagonal of Bt.
inline double solid_normal_over_G(double root, double b_aa, double b11, double b22, double b33) {
  const double tr = b11 + b22 + b33;
  return root * (b_aa - tr / 3.0);
}

// sqrt(phi) Bt_AB (A != B) at the edge (i, j, k) of staggering T from its Bt_AB, sqrt(phi)
// averaged from the four centres around it.
template <Stagger T, class Root>
inline double solid_shear_over_G(const Root& root, double b_ab, int i, int j, int k) {
  return average<Stagger::cell, T>(root, i, j, k) * b_ab;
}

// sqrt(phi) (Bt - tr(Bt)/3 I)_AB at tensor_location(A, B); the solid stress is G times
// this. sqrt(phi) is averaged to the edges from the four surrounding centres. `root(i, j, k)`
// gives sqrt_phi(phi) at centre (i, j, k): the step's kernels read it from a field filled
// once (solid_root), since a square root costs as much as a division and each centre feeds
// seven stress points.
template <int A, int B, class Root>
inline double solid_stress_over_G(const FieldSet& s, const Root& root, int i, int j, int k) {
  if constexpr (A == B) {
    return solid_normal_over_G(root(i, j, k), s.B(A)(i, j, k), s.B(0)(i, j, k), s.B(1)(i, j, k), s.B(2)(i, j, k));
  } else {
    return solid_shear_over_G<tensor_location(A, B)>(root, s.B(A, B)(i, j, k), i, j, k);
  }
}

// The same with sqrt(phi) taken where it is read.
template <int A, int B>
inline double solid_stress_over_G(const FieldSet& s, int i, int j, int k) {
  const Field& phi = s.phi();
  return solid_stress_over_G<A, B>(s, [&](int a, int b, int c) { return sqrt_phi(phi(a, b, c)); }, i, j, k);
}

}  // namespace efsi
