// docs/numerics.md, "Diagnostics": the kinetic-energy budget -dK/dt + I - eps_s - eps_f = 0 and the
// flow's state. The dissipation sums pair each stress component with the strain rate at
// the same place, with half weight on the wall planes, which is exactly what the
// momentum equation's stress divergence does to the energy (summation by parts with the
// mirrored ghosts), so the budget closes to the time-stepping error.
#include "flow_diagnostics.hpp"

#include <cmath>

#include "constitutive.hpp"

namespace efsi {

FlowDiagnostics flow_diagnostics(const FsiState& state, const Physics& ph) {
  const FieldSet s = state.fields();
  const CartDecomposition& dec = s.decomp();
  const Domain& dom = s.domain();
  const InverseSpacing inv(dom);
  const Int3 n = dec.local();
  const int wall_lo = dec.wall_row_below(), wall_hi = dec.wall_row_above();
  const Field &u = s.vel(X), &v = s.vel(Y), &w = s.vel(Z), &phi = s.phi();
  const double two_mu = 2.0 * ph.mu;

  double ke = 0, su = 0, ef = 0, es = 0, d2 = 0, sphi = 0;
  double dmax = 0, umax = 0;
#pragma omp parallel for collapse(2) schedule(static) reduction(+ : ke, su, ef, es, d2, sphi) reduction(max : dmax, umax)
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) {
        const double a = u(i, j, k), b = v(i, j, k), c = w(i, j, k);
        ke += a * a + b * b + c * c;
        su += a;
        umax = std::max({umax, std::fabs(a), std::fabs(b), std::fabs(c)});
        sphi += phi(i, j, k);
        const double d11 = strain_rate<0, 0>(s, inv, i, j, k), d22 = strain_rate<1, 1>(s, inv, i, j, k),
                     d33 = strain_rate<2, 2>(s, inv, i, j, k);
        const double div = d11 + d22 + d33;
        d2 += div * div;
        dmax = std::max(dmax, std::fabs(div));
        ef += two_mu * (d11 * d11 + d22 * d22 + d33 * d33);
        es += ph.G * (solid_stress_over_G<0, 0>(s, i, j, k) * d11 + solid_stress_over_G<1, 1>(s, i, j, k) * d22 +
                      solid_stress_over_G<2, 2>(s, i, j, k) * d33);
      }

  // Edges: off-diagonal terms count twice in the double contraction. Edges staggered
  // in y include the top wall plane on the top rank (owned_end).
  const int y_edge_end = s.B(0, 1).owned_end(Y);
#pragma omp parallel for collapse(2) schedule(static) reduction(+ : ef, es)
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < y_edge_end; ++j)
      for (int i = 0; i < n[X]; ++i) {
        const double wt = (j == wall_lo || j == wall_hi) ? 0.5 : 1.0;
        const double d12 = strain_rate<0, 1>(s, inv, i, j, k), d23 = strain_rate<1, 2>(s, inv, i, j, k);
        ef += wt * 2.0 * two_mu * (d12 * d12 + d23 * d23);
        es += wt * 2.0 * ph.G * (solid_stress_over_G<0, 1>(s, i, j, k) * d12 + solid_stress_over_G<1, 2>(s, i, j, k) * d23);
        if (j < n[Y]) {
          const double d13 = strain_rate<0, 2>(s, inv, i, j, k);
          ef += 2.0 * two_mu * d13 * d13;
          es += 2.0 * ph.G * solid_stress_over_G<0, 2>(s, i, j, k) * d13;
        }
      }

  double sums[6] = {ke, su, ef, es, d2, sphi}, g[6];
  double maxes[2] = {dmax, umax}, gm[2];
  MPI_Allreduce(sums, g, 6, MPI_DOUBLE, MPI_SUM, dec.comm());
  MPI_Allreduce(maxes, gm, 2, MPI_DOUBLE, MPI_MAX, dec.comm());

  const double cells = static_cast<double>(product(dom.cells));
  FlowDiagnostics d;
  d.kinetic = 0.5 * ph.rho * g[0] / cells;
  d.input = ph.force * g[1] / cells;
  d.eps_fluid = g[2] / cells;
  d.eps_solid = g[3] / cells;
  d.div_rms = std::sqrt(g[4] / cells);
  d.div_max = gm[0];
  d.u_max = gm[1];
  d.flow_rate = g[1] / cells * dom.length[Y] * dom.length[Z];
  d.solid_fraction = g[5] / cells;
  return d;
}

}  // namespace efsi
