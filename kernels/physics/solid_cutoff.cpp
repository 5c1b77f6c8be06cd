// Why a cut-off: WENO transport smears a thin film of solid fraction (phi ~ 1e-4 .. 1e-2) off
// every particle.  That film is fluid in all but name, yet it carries Bt = sqrt(phi) B with
// the B of fluid sheared since t = 0, growing as (shear x t)^2, and the six components,
// transported one by one, lose positive definiteness there.  An indefinite Bt is a negative
// stiffness; in the paper's accuracy case it is what blows up, in the film between the
// particles and the walls (docs/numerics.md, "Solid cut-off", has the figures).
#include "solid_cutoff.hpp"

#include <bit>
#include <cstdint>

#include "box_loops.hpp"
#include "constitutive.hpp"
#include "fsi_equations.hpp"
#include "stencils.hpp"

namespace efsi {
namespace {

// x where `mask` is all ones, y where it is zero: a select GCC vectorises with the square
// root computed unconditionally (a conditional square root is control flow it will not
// if-convert, and the loop stays scalar).
inline double pick(std::uint64_t mask, double x, double y) {
  return std::bit_cast<double>((std::bit_cast<std::uint64_t>(x) & mask) | (std::bit_cast<std::uint64_t>(y) & ~mask));
}

// The three diagonal components together: one square root per centre serves all three.
void reset_normal(const Field& phi, const Field& phi_new, std::array<Field, 6>& b, double cutoff, const Box& cells) {
  Field &b0 = b[0], &b1 = b[1], &b2 = b[2];
  for_box(cells, [&](int i, int j, int k) {
    const std::uint64_t debris = solid_debris<Stagger::cell>(phi, cutoff, i, j, k) ? ~std::uint64_t{0} : 0;
    const double unstrained = sqrt_phi(phi_new(i, j, k));
    b0(i, j, k) = pick(debris, unstrained, b0(i, j, k));
    b1(i, j, k) = pick(debris, unstrained, b1(i, j, k));
    b2(i, j, k) = pick(debris, unstrained, b2(i, j, k));
  });
}

template <int A, int B>
void reset_shear(const Field& phi, Field& b, double cutoff, const Box& cells) {
  constexpr Stagger T = tensor_location(A, B);
  for_box(owned_extent(b, cells), [&](int i, int j, int k) {
    const double old = b(i, j, k);
    b(i, j, k) = solid_debris<T>(phi, cutoff, i, j, k) ? 0.0 : old;
  });
}

}  // namespace

void reset_solid_debris(const Field& phi, const Field& phi_new, std::array<Field, 6>& B_new, double cutoff,
                        const Box& cells) {
  if (!(cutoff > 0.0)) return;
  reset_normal(phi, phi_new, B_new, cutoff, cells);
  reset_shear<0, 1>(phi, B_new[3], cutoff, cells);
  reset_shear<0, 2>(phi, B_new[4], cutoff, cells);
  reset_shear<1, 2>(phi, B_new[5], cutoff, cells);
}

}  // namespace efsi
