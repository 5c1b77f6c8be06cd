// Why a cut-off: WENO transport smears a thin film of solid fraction (phi ~ 1e-4 .. 1e-2) off
// every particle.  That film is fluid in all but name, yet it carries Bt = sqrt(phi) B with
// the B of fluid sheared since t = 0, growing as (shear x t)^2, and the six components,
// transported one by one, lose positive definiteness there.  An indefinite Bt is a negative
// stiffness; in the paper's accuracy case it is what blows up, in the film between the
// particles and the walls (docs/numerics.md, "Solid cut-off", has the figures).
#include "solid_cutoff.hpp"

#include "box_loops.hpp"
#include "constitutive.hpp"
#include "fsi_equations.hpp"
#include "stencils.hpp"

namespace efsi {
namespace {

void reset_normal(const Field& phi, const Field& phi_new, std::array<Field, 6>& b, double cutoff, const Box& cells) {
  Field &b0 = b[0], &b1 = b[1], &b2 = b[2];
  for_box(cells, [&](int i, int j, int k) { reset_normal_at(phi, phi_new, b0, b1, b2, cutoff, i, j, k); });
}

}  // namespace

template <int A, int B>
void reset_shear_debris(const Field& phi, Field& b, double cutoff, const Box& cells) {
  if (!(cutoff > 0.0)) return;
  for_box(owned_extent(b, cells), [&](int i, int j, int k) { reset_shear_at<A, B>(phi, b, cutoff, i, j, k); });
}
template void reset_shear_debris<0, 1>(const Field&, Field&, double, const Box&);
template void reset_shear_debris<0, 2>(const Field&, Field&, double, const Box&);
template void reset_shear_debris<1, 2>(const Field&, Field&, double, const Box&);

void reset_solid_debris(const Field& phi, const Field& phi_new, std::array<Field, 6>& B_new, double cutoff,
                        const Box& cells) {
  if (!(cutoff > 0.0)) return;
  reset_normal(phi, phi_new, B_new, cutoff, cells);
  reset_shear_debris<0, 1>(phi, B_new[3], cutoff, cells);
  reset_shear_debris<0, 2>(phi, B_new[4], cutoff, cells);
  reset_shear_debris<1, 2>(phi, B_new[5], cutoff, cells);
}

}  // namespace efsi
