// The transport of phi and Bt (docs/numerics.md, "Spatial discretisation"): WENO5 upwind
// advection and the upper-convected stretching of Bt.  Each line of output points is
// computed by one vectorised loop per advection axis and per stretching term, partial sums
// kept in scratch arrays (box_loops.hpp): one loop over all of them spills its registers,
// and GCC then leaves the WENO derivative out of line and the loops scalar.  The sums are
// formed in the order of the equations as written, so the split changes no bit.
#include <type_traits>

#include "box_loops.hpp"
#include "constitutive.hpp"
#include "fsi_equations.hpp"
#include "weno5.hpp"

namespace efsi {
namespace {

using Inv = InverseSpacing;

// v_M . d q / d x_M with the WENO5 upwind derivative, q at location T.
template <Stagger T, int M>
[[gnu::always_inline]] inline double weno_advection(const FieldSet& s, const Inv& inv, const Field& q, int i, int j, int k) {
  const double vel = average<face_location(M), T>(s.vel(M), i, j, k);
  const std::ptrdiff_t st = M == X ? 1 : M == Y ? q.stride_y() : q.stride_z();
  const double* c = q.data() + q.index(i, j, k);
  return vel * weno5_derivative(c[-3 * st], c[-2 * st], c[-st], c[0], c[st], c[2 * st], c[3 * st], vel, inv.h[M]);
}

// (L.Bt + Bt.L^T)_AB at tensor_location(A, B), each factor averaged to that location.
template <int A, int B, int M>
[[gnu::always_inline]] inline double upper_convected_term(const FieldSet& s, const Inv& inv, int i, int j, int k) {
  constexpr Stagger T = tensor_location(A, B);
  auto L = [&](auto a_tag, auto m_tag) {
    constexpr int a = decltype(a_tag)::value, m = decltype(m_tag)::value;
    return average<tensor_location(a, m), T>([&](int x, int y, int z) { return grad_v<a, m>(s, inv, x, y, z); }, i,
                                             j, k);
  };
  using IA = std::integral_constant<int, A>;
  using IB = std::integral_constant<int, B>;
  using IM = std::integral_constant<int, M>;
  const double b_mb = average<tensor_location(M, B), T>(s.B(M, B), i, j, k);
  const double b_am = average<tensor_location(A, M), T>(s.B(A, M), i, j, k);
  return L(IA{}, IM{}) * b_mb + b_am * L(IB{}, IM{});
}

// sum_M (L.Bt + Bt.L^T)_AB, the terms added along the line in the order M = X, Y, Z.
template <int A, int B, class Ln>
inline void stretching_line(const FieldSet& s, const Inv& inv, const Ln& l, double* uc) {
  along(l, [&](int t, int i, int j, int k) { uc[t] = upper_convected_term<A, B, X>(s, inv, i, j, k); });
  along(l, [&](int t, int i, int j, int k) { uc[t] += upper_convected_term<A, B, Y>(s, inv, i, j, k); });
  along(l, [&](int t, int i, int j, int k) { uc[t] += upper_convected_term<A, B, Z>(s, inv, i, j, k); });
}

// adv = sum over the axes M0, M... of v_M dq/dx_M, added in the order given.
template <Stagger T, int M0, int... M, class Ln>
inline void advection_line(const FieldSet& s, const Inv& inv, const Field& q, const Ln& l, double* adv) {
  along(l, [&](int t, int i, int j, int k) { adv[t] = weno_advection<T, M0>(s, inv, q, i, j, k); });
  (along(l, [&](int t, int i, int j, int k) { adv[t] += weno_advection<T, M>(s, inv, q, i, j, k); }), ...);
}

template <int A, int B>
void transport_component(const FieldSet& s, Field& out, const Box& cells) {
  const Inv inv(s.domain());
  constexpr Stagger T = tensor_location(A, B);
  const Field& q = s.B(A, B);
  // The top wall face of a field staggered in y is owned (see field.hpp).
  const Box box = owned_extent(q, cells);
  const int wall_lo = s.decomp().wall_row_below(), wall_hi = s.decomp().wall_row_above();
  auto pieces = [&](const Box& b, bool wall) {
    for_lines<2>(b, [&](const auto& l, double* adv) {
      double* uc = adv + l.n;
      // On a wall face v = 0 exactly, and the y stencil would reach past the ghosts.
      if (wall) advection_line<T, X, Z>(s, inv, q, l, adv);
      else advection_line<T, X, Z, Y>(s, inv, q, l, adv);
      stretching_line<A, B>(s, inv, l, uc);
      along(l, [&](int t, int i, int j, int k) { out(i, j, k) = uc[t] - adv[t]; });
    });
  };
  if constexpr (is_staggered(T, Y)) split_wall_rows(box, wall_lo, wall_hi, pieces);
  else pieces(box, false);
}

template <int A, int B>
void stretching_component(const FieldSet& s, double dt, const Field& base, Field& out, const Box& cells) {
  const Inv inv(s.domain());
  for_lines<1>(owned_extent(out, cells), [&](const auto& l, double* uc) {
    stretching_line<A, B>(s, inv, l, uc);
    along(l, [&](int t, int i, int j, int k) { out(i, j, k) = base(i, j, k) + dt * uc[t]; });
  });
}

// tau_AB (A != B) from s's velocity and Bt* = base + dt (L.Bt + Bt.L^T)_AB, Bt* kept in the line.
template <int A, int B>
void stretched_shear_component(const FieldSet& s, const Physics& ph, double dt, const Field& base, const Field& root,
                               Field& tau, const Box& cells) {
  const Inv inv(s.domain());
  constexpr Stagger T = tensor_location(A, B);
  const double two_mu = 2.0 * ph.mu, G = ph.G;
  const auto r = [&root](int a, int b, int c) { return root(a, b, c); };
  for_lines<1>(owned_extent(tau, cells), [&](const auto& l, double* uc) {
    stretching_line<A, B>(s, inv, l, uc);
    along(l, [&](int t, int i, int j, int k) {
      const double b_star = base(i, j, k) + dt * uc[t];
      tau(i, j, k) = two_mu * strain_rate<A, B>(s, inv, i, j, k) + G * solid_shear_over_G<T>(r, b_star, i, j, k);
    });
  });
}

// tau_11, tau_22, tau_33 likewise: each needs the three diagonal Bt* for the trace.
void stretched_normal_components(const FieldSet& s, const Physics& ph, double dt, const std::array<Field, 6>& base,
                                 const Field& root, std::array<Field, 6>& tau, const Box& cells) {
  const Inv inv(s.domain());
  const double two_mu = 2.0 * ph.mu, G = ph.G;
  for_lines<3>(cells, [&](const auto& l, double* uc) {
    double* const u[3] = {uc, uc + l.n, uc + 2 * l.n};
    stretching_line<0, 0>(s, inv, l, u[0]);
    stretching_line<1, 1>(s, inv, l, u[1]);
    stretching_line<2, 2>(s, inv, l, u[2]);
    auto normal = [&](auto a_tag) {
      constexpr int A = decltype(a_tag)::value;
      along(l, [&](int t, int i, int j, int k) {
        const double b0 = base[0](i, j, k) + dt * u[0][t], b1 = base[1](i, j, k) + dt * u[1][t],
                     b2 = base[2](i, j, k) + dt * u[2][t];
        const double b_aa = A == 0 ? b0 : A == 1 ? b1 : b2;
        tau[A](i, j, k) = two_mu * strain_rate<A, A>(s, inv, i, j, k) +
                          G * solid_normal_over_G(root(i, j, k), b_aa, b0, b1, b2);
      });
    };
    normal(std::integral_constant<int, 0>{});
    normal(std::integral_constant<int, 1>{});
    normal(std::integral_constant<int, 2>{});
  });
}

void phi_transport(const FieldSet& s, Field& dphidt, const Box& cells) {
  const Inv inv(s.domain());
  for_lines<1>(cells, [&](const auto& l, double* adv) {
    advection_line<Stagger::cell, X, Y, Z>(s, inv, s.phi(), l, adv);
    along(l, [&](int t, int i, int j, int k) { dphidt(i, j, k) = -adv[t]; });
  });
}

}  // namespace

void transport_tendency(const FieldSet& s, Field& dphidt, std::array<Field, 6>& dBdt, const Box& cells) {
  phi_transport(s, dphidt, cells);
  transport_component<0, 0>(s, dBdt[0], cells);
  transport_component<1, 1>(s, dBdt[1], cells);
  transport_component<2, 2>(s, dBdt[2], cells);
  transport_component<0, 1>(s, dBdt[3], cells);
  transport_component<0, 2>(s, dBdt[4], cells);
  transport_component<1, 2>(s, dBdt[5], cells);
}

void add_stretching(const FieldSet& s, double dt, const std::array<Field, 6>& base, std::array<Field, 6>& out,
                    const Box& cells) {
  stretching_component<0, 0>(s, dt, base[0], out[0], cells);
  stretching_component<1, 1>(s, dt, base[1], out[1], cells);
  stretching_component<2, 2>(s, dt, base[2], out[2], cells);
  stretching_component<0, 1>(s, dt, base[3], out[3], cells);
  stretching_component<0, 2>(s, dt, base[4], out[4], cells);
  stretching_component<1, 2>(s, dt, base[5], out[5], cells);
}

void stretched_stress_owned(const FieldSet& s, const Physics& ph, double dt, const std::array<Field, 6>& base,
                            const Field& root, std::array<Field, 6>& tau) {
  const Box owned{{0, 0, 0}, s.decomp().local()};
  stretched_normal_components(s, ph, dt, base, root, tau, owned);
  stretched_shear_component<0, 1>(s, ph, dt, base[3], root, tau[3], owned);
  stretched_shear_component<0, 2>(s, ph, dt, base[4], root, tau[4], owned);
  stretched_shear_component<1, 2>(s, ph, dt, base[5], root, tau[5], owned);
}

}  // namespace efsi
