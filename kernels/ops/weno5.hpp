#pragma once
// Upwind-biased fifth-order WENO derivative in the Hamilton-Jacobi form of Jiang and Peng
// (SIAM J. Sci. Comput. 21, 2000) with the Jiang-Shu smoothness indicators and weights
// alpha_k = gamma_k / (eps + beta_k)^2, eps = 1e-6: the non-conservative advection v.grad q
// of phi and Bt (docs/numerics.md, "Staggered grid"). It runs for 7 fields per cell per axis per step, so it
// is branch-free (the upwind side is a select, not a jump), spends one division, and works
// on the raw differences of q: the weights depend only on the ratios of the indicators, so
// the spacing and the sign of the upwind side come out as one factor at the end.
//
// Why the classic weights and not WENO-Z (Borges et al. 2008) or eps scaled with h^2:
// - Order. Near points where q'' = 0 (critical points of the reconstructed derivative) the
//   Jiang-Shu weights stay away from the linear ones and the order sags. On sin(2 pi (x+s))
//   + 0.3 cos(4 pi (x+s)) over 100 shifts s the worst max-norm order is 4.68 (N 32->64),
//   4.75 (64->128), 4.48 (128->256). WENO-Z keeps 5.15, 5.31, 5.00; eps = h^2 changes
//   nothing visible (the indicators there are far above h^2).
// - Stability, which decides it. The paper's explicit Euler, whose amplification on a
//   resolved wave is |1 - i CFL theta| > 1: only the scheme's own dissipation holds it. In
//   1-D periodic transport at the paper's CFL 0.06 on 128 cells for the accuracy case's
//   40000 steps, WENO-Z blows up (|q| > 1e3 after 21000-26000 steps for a step, tanh fronts
//   one and two cells wide, and a smooth bump) while Jiang-Shu stays bounded (overshoot 0.07
//   for the one-cell tanh front, 0.04 for the step); eps = h^2 or eps = 1e-6 on raw
//   differences overshoot by 2 to 15 on the same fronts. The extra dissipation that costs
//   Jiang-Shu its order near critical points is what keeps Euler transport bounded.
//
// Epsilon keeps the weights finite where all indicators vanish (phi = Bt = 0 in pure fluid)
// and, as in Jiang-Peng, applies to indicators built from the difference quotients
// (q_{i+1} - q_i) / h, so it is in units of (q / length)^2: with q of order one (phi, Bt) and
// the paper's lengths (h ~ 0.06, particles ~ 1) every resolved feature sits far above it.
// In units where h is thousands, it would dominate and leave the linear, unstable scheme.
#include <cmath>

#include "mul_add.hpp"

namespace efsi {

inline constexpr double weno5_epsilon = 1e-6;

// The constants of one axis of spacing h = 1 / inv_h.  eps applies to indicators of the
// difference quotients; on raw differences, with the indicators taken 4 times (below), it
// is 4 eps h^2.
struct Weno5Axis {
  double scale;    // inv_h / 6: the candidates below are 6 h times a derivative
  double epsilon;  // 4 eps h^2
  explicit Weno5Axis(double inv_h) : scale(inv_h / 6.0), epsilon(4.0 * weno5_epsilon / (inv_h * inv_h)) {}
};

// 6 h dq/dx from the five raw differences d1..d5 ordered from the far upwind end: for
// left-biased data d_k = q_{k-2} - q_{k-3}, i.e. the differences across [i-3,i-2], ...,
// [i+1,i+2]; eps4 is Weno5Axis::epsilon.  Odd in d, exactly: every operation commutes with
// negation, so a mirrored stencil gives the negated value to the bit.
[[gnu::always_inline]] inline double weno5_upwind(double d1, double d2, double d3, double d4, double d5,
                                                  double eps4) {
  // Candidate third-order derivatives, times 6 h.
  const double p1 = mul_add(11.0, d3, mul_add(-7.0, d2, 2.0 * d1));
  const double p2 = mul_add(2.0, d4, mul_add(5.0, d3, -d2));
  const double p3 = mul_add(5.0, d4, mul_add(2.0, d3, -d5));

  // Jiang-Shu indicators 13/12 c^2 + 1/4 l^2, times 4 (the weights depend only on their
  // ratios).
  const double c1 = mul_add(-2.0, d2, d1 + d3), l1 = mul_add(3.0, d3, mul_add(-4.0, d2, d1));
  const double c2 = mul_add(-2.0, d3, d2 + d4), l2 = d2 - d4;
  const double c3 = mul_add(-2.0, d4, d3 + d5), l3 = mul_add(3.0, d3, mul_add(-4.0, d4, d5));
  constexpr double k133 = 13.0 / 3.0;
  const double s1 = mul_add(k133 * c1, c1, mul_add(l1, l1, eps4));
  const double s2 = mul_add(k133 * c2, c2, mul_add(l2, l2, eps4));
  const double s3 = mul_add(k133 * c3, c3, mul_add(l3, l3, eps4));

  // alpha_k = gamma_k / s_k^2 times 10 (s1 s2 s3)^2 leaves the normalised weights unchanged
  // and trades three divisions for multiplications.  Each s_k >= eps4 keeps the products
  // clear of underflow for any h above 1e-30; they overflow only for |d| > 1e37.
  const double q1 = s1 * s1, q2 = s2 * s2, q3 = s3 * s3;
  const double a1 = q2 * q3;
  const double a2 = (6.0 * q1) * q3;
  const double a3 = (3.0 * q1) * q2;
  return mul_add(a3, p3, mul_add(a2, p2, a1 * p1)) / (a1 + a2 + a3);
}

// 6 h dq/dx at the centre point q0 from the seven points q_{-3}..q_{+3}, read from the
// left-biased stencil q_{-3}..q_{+2} when `left`, else from the right-biased q_{-2}..q_{+3}
// with the sign of the result flipped.
[[gnu::always_inline]] inline double weno5_upwind_side(double qm3, double qm2, double qm1, double q0, double qp1,
                                                       double qp2, double qp3, bool left, double eps4) {
  // The right-biased differences are the negated left-biased ones of the mirrored data, so
  // one evaluation serves both sides and the choice compiles to selects.
  const double a = left ? qm3 : qp3;
  const double b = left ? qm2 : qp2;
  const double c = left ? qm1 : qp1;
  const double e = left ? qp1 : qm1;
  const double f = left ? qp2 : qm2;
  return weno5_upwind(b - a, c - b, q0 - c, e - q0, f - e, eps4);
}

// The advection term velocity * dq/dx, the upwind side taken from the velocity's sign.
// The side's sign and the velocity's cancel: the factor is |velocity| h^-1 / 6.
[[gnu::always_inline]] inline double weno5_advection(double qm3, double qm2, double qm1, double q0, double qp1,
                                                     double qp2, double qp3, double velocity, const Weno5Axis& ax) {
  return (std::fabs(velocity) * ax.scale) *
         weno5_upwind_side(qm3, qm2, qm1, q0, qp1, qp2, qp3, velocity > 0.0, ax.epsilon);
}

// dq/dx alone, for points spaced h = 1 / inv_h.
inline double weno5_derivative(double qm3, double qm2, double qm1, double q0, double qp1, double qp2, double qp3,
                               double velocity, double inv_h) {
  const Weno5Axis ax(inv_h);
  const bool left = velocity > 0.0;
  return (left ? ax.scale : -ax.scale) * weno5_upwind_side(qm3, qm2, qm1, q0, qp1, qp2, qp3, left, ax.epsilon);
}

}  // namespace efsi
