#include "acm.hpp"

#include <cmath>

#include "acm_work.hpp"
#include "compute_model.hpp"

namespace efsi {

AcmCoefficients acm_coefficients(const AcmMoments& m) {
  AcmCoefficients c;
  // A2 = <(Lap D*)^2> = 0 only when D* is harmonic, i.e. constant (zero at rest):
  // nothing to correct.
  if (!(m.A2 > 0.0)) return c;
  const double det = m.A2 * m.A3 - m.B2 * m.B2;
  // Cauchy-Schwarz makes det >= 0; below round-off of its terms the 2x2 system is
  // singular (Lap p parallel to Lap D*, or p harmonic) and the optimum not unique.
  if (det > 1e-12 * m.A2 * m.A3) {
    const double a = (m.A1 * m.A3 + m.B1 * m.B2) / det;
    const double b = -(m.A1 * m.B2 + m.A2 * m.B1) / det;
    if (b >= 0.0 && a > 0.0) {
      c.a = a, c.b = b, c.branch = AcmCoefficients::Branch::optimal;
      return c;
    }
  }
  // gamma = 0: a = A1 / A2 minimises over a alone; A1 = <|grad D*|^2> >= 0.
  c.a = std::max(m.A1 / m.A2, 0.0);
  c.b = 0.0;
  c.branch = c.a > 0.0 ? AcmCoefficients::Branch::gamma_zero : AcmCoefficients::Branch::no_update;
  return c;
}

AcmMoments acm_moments(const Field& div, const Field& p, const Domain& domain, MPI_Comm comm,
                       RegionTimers& timers) {
  const double inv_h2[3] = {1.0 / (domain.spacing(X) * domain.spacing(X)),
                            1.0 / (domain.spacing(Y) * domain.spacing(Y)),
                            1.0 / (domain.spacing(Z) * domain.spacing(Z))};
  const Int3 n = div.n();
  double s[7] = {0, 0, 0, 0, 0, 0, 0};
  {
    RegionTimers::Scope t(&timers, Region::compute);
    // The sums are the lambda's own locals: a reduction over captured references costs
    // a load and a store through the closure per term (counted gate: +4% instructions).
    compute_stage(kAcmMoments, double(product(n)), [&] {
      double a1 = 0, a2 = 0, a3 = 0, b1 = 0, b2 = 0, sp = 0, sd = 0;
#pragma omp parallel for collapse(2) schedule(static) reduction(+ : a1, a2, a3, b1, b2, sp, sd)
      for (int k = 0; k < n[Z]; ++k)
        for (int j = 0; j < n[Y]; ++j)
          for (int i = 0; i < n[X]; ++i) {
            const double d = div(i, j, k), ld = laplacian(div, inv_h2, i, j, k), lp = laplacian(p, inv_h2, i, j, k);
            a1 -= d * ld;
            a2 += ld * ld;
            a3 += lp * lp;
            b1 += d * lp;
            b2 += ld * lp;
            sp += p(i, j, k);
            sd += d;
          }
      s[0] = a1, s[1] = a2, s[2] = a3, s[3] = b1, s[4] = b2, s[5] = sp, s[6] = sd;
    });
  }
  double g[7];
  {
    RegionTimers::Scope t(&timers, Region::reduce);
    MPI_Allreduce(s, g, 7, MPI_DOUBLE, MPI_SUM, comm);
  }
  const double inv_cells = 1.0 / static_cast<double>(product(domain.cells));
  return {g[0] * inv_cells, g[1] * inv_cells, g[2] * inv_cells, g[3] * inv_cells,
          g[4] * inv_cells, g[5] * inv_cells, g[6] * inv_cells};
}

void AcmPressure::increment(PressureInputs& in) {
  const Field& p = in.state.p();
  Field& div = in.work.div;
  Field& dp = in.work.dp;
  moments_ = acm_moments(div, p, in.state.domain(), in.state.decomp().comm(), in.timers);
  const AcmMoments& m = moments_;
  // Non-finite moments make dp non-finite; the solver's blow-up check then stops the run
  // and says where.
  coeff_ = acm_coefficients(m);
  const double a = coeff_.a, b = coeff_.b, dt = in.dt;
  report_.beta = std::sqrt(a) / dt;
  report_.gamma = a > 0 ? b / a : 0.0;

  // dp = -(a/dt) (gamma p + D*) = -(b p + a D*) / dt, shifted so that <p + dp> = 0.
  const double shift = m.mean_p - (b * m.mean_p + a * m.mean_div) / dt;
  const Int3 n = dp.n();
  RegionTimers::Scope t(&in.timers, Region::compute);
  auto set = [&](int i, int j, int k) { dp(i, j, k) = -(b * p(i, j, k) + a * div(i, j, k)) / dt - shift; };
  compute_stage(kAcmUpdate, double(product(n)), [&] {
#pragma omp parallel for collapse(2) schedule(static)
    for (int k = 0; k < n[Z]; ++k)
      for (int j = 0; j < n[Y]; ++j)
        for (int i = 0; i < n[X]; ++i) set(i, j, k);
    // The low face ghosts, read by grad dp on the owned faces: p and D* are valid there.
    for (int k = 0; k < n[Z]; ++k)
      for (int j = 0; j < n[Y]; ++j) set(-1, j, k);
    for (int k = 0; k < n[Z]; ++k)
      for (int i = 0; i < n[X]; ++i) set(i, -1, k);
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) set(i, j, -1);
  });
}

}  // namespace efsi
