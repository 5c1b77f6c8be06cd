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
#include "mul_add.hpp"
#include "rate_output.hpp"
#include "solid_cutoff.hpp"
#include "weno5.hpp"

namespace efsi {
namespace {

// The inverse spacings and, per axis, the WENO5 constants, formed once per call rather than
// per point (each holds a division).
struct Inv : InverseSpacing {
  Weno5Axis weno[3];
  explicit Inv(const Domain& d) : InverseSpacing(d), weno{Weno5Axis(h[X]), Weno5Axis(h[Y]), Weno5Axis(h[Z])} {}
};

// v_M . d q / d x_M with the WENO5 upwind derivative, q at location T.
template <Stagger T, int M>
[[gnu::always_inline]] inline double weno_advection(const FieldSet& s, const Inv& inv, const Field& q, int i, int j, int k) {
  const double vel = average<face_location(M), T>(s.vel(M), i, j, k);
  const std::ptrdiff_t st = M == X ? 1 : M == Y ? q.stride_y() : q.stride_z();
  const double* c = q.data() + q.index(i, j, k);
  return weno5_advection(c[-3 * st], c[-2 * st], c[-st], c[0], c[st], c[2 * st], c[3 * st], vel, inv.weno[M]);
}

// (L.Bt + Bt.L^T)_AB at tensor_location(A, B), each factor averaged to that location.
template <int A, int B, int M>
[[gnu::always_inline]] inline double upper_convected_term(const FieldSet& s, const Inv& inv, int i, int j, int k) {
  constexpr Stagger T = tensor_location(A, B);
  const double b_mb = average<tensor_location(M, B), T>(s.B(M, B), i, j, k);
  const double b_am = average<tensor_location(A, M), T>(s.B(A, M), i, j, k);
  return mul_add(grad_v_at<A, M, T>(s, inv, i, j, k), b_mb, b_am * grad_v_at<B, M, T>(s, inv, i, j, k));
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

// dBt_AB/dt = (L.Bt + Bt.L^T)_AB - v.grad Bt_AB on line l (adv, uc: 2 l.n), written through
// `store` (rate_output.hpp).  On a wall face row v = 0 exactly, and the y stencil would
// reach past the ghosts.
template <int A, int B, class Store, class Ln>
inline void component_line(const FieldSet& s, const Inv& inv, const Store& store, Field& out, const Ln& l, bool wall,
                           double* adv) {
  constexpr Stagger T = tensor_location(A, B);
  const Field& q = s.B(A, B);
  double* uc = adv + l.n;
  if (wall) advection_line<T, X, Z>(s, inv, q, l, adv);
  else advection_line<T, X, Z, Y>(s, inv, q, l, adv);
  stretching_line<A, B>(s, inv, l, uc);
  along(l, [&](int t, int i, int j, int k) { out(i, j, k) = store(q, i, j, k, uc[t] - adv[t]); });
}

template <class Store, class Ln>
inline void phi_line(const FieldSet& s, const Inv& inv, const Store& store, Field& dphidt, const Ln& l, double* adv) {
  const Field& phi = s.phi();
  advection_line<Stagger::cell, X, Y, Z>(s, inv, phi, l, adv);
  along(l, [&](int t, int i, int j, int k) { dphidt(i, j, k) = store(phi, i, j, k, -adv[t]); });
}

template <int A, int B, class Store>
void transport_component(const FieldSet& s, const Store& store, Field& out, const Box& cells) {
  const Inv inv(s.domain());
  constexpr Stagger T = tensor_location(A, B);
  // The top wall face of a field staggered in y is owned (see field.hpp).
  const Box box = owned_extent(s.B(A, B), cells);
  const int wall_lo = s.decomp().wall_row_below(), wall_hi = s.decomp().wall_row_above();
  auto pieces = [&](const Box& b, bool wall) {
    for_lines<2>(b, [&](const auto& l, double* adv) { component_line<A, B>(s, inv, store, out, l, wall, adv); });
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

// tau_AB (A != B) on line l from s's velocity and Bt* = base + dt (L.Bt + Bt.L^T)_AB, Bt*
// kept in the line.
template <int A, int B, class Ln>
inline void stretched_shear_line(const FieldSet& s, const Inv& inv, double two_mu, double G, double dt,
                                 const Field& base, const Field& root, Field& tau, const Ln& l, double* uc) {
  constexpr Stagger T = tensor_location(A, B);
  const auto r = [&root](int a, int b, int c) { return root(a, b, c); };
  stretching_line<A, B>(s, inv, l, uc);
  along(l, [&](int t, int i, int j, int k) {
    const double b_star = base(i, j, k) + dt * uc[t];
    tau(i, j, k) = two_mu * strain_rate<A, B>(s, inv, i, j, k) + G * solid_shear_over_G<T>(r, b_star, i, j, k);
  });
}

// tau_11, tau_22, tau_33 likewise: each needs the three diagonal Bt* for the trace (uc: 3 l.n).
template <class Ln>
inline void stretched_normal_line(const FieldSet& s, const Inv& inv, double two_mu, double G, double dt,
                                  const std::array<Field, 6>& base, const Field& root, std::array<Field, 6>& tau,
                                  const Ln& l, double* uc) {
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
      tau[A](i, j, k) = two_mu * strain_rate<A, A>(s, inv, i, j, k) + G * solid_normal_over_G(root(i, j, k), b_aa, b0, b1, b2);
    });
  };
  normal(std::integral_constant<int, 0>{});
  normal(std::integral_constant<int, 1>{});
  normal(std::integral_constant<int, 2>{});
}

template <class Store>
void phi_transport(const FieldSet& s, const Store& store, Field& dphidt, const Box& cells) {
  const Inv inv(s.domain());
  for_lines<1>(cells, [&](const auto& l, double* adv) { phi_line(s, inv, store, dphidt, l, adv); });
}

// The part of line l from its first to its last point whose Bt component at location T the
// solid cut-off keeps (solid_debris false); n = 0 when it keeps none.
template <Stagger T, class Ln>
Ln kept_part(const Field& phi, double cutoff, const Ln& l) {
  if (!(cutoff > 0.0)) return l;
  auto kept = [&](int t) {
    const int i = Ln::along_y ? l.i : l.i + t, j = Ln::along_y ? l.j + t : l.j;
    return !solid_debris<T>(phi, cutoff, i, j, l.k);
  };
  int first = 0, last = l.n;
  while (first < l.n && !kept(first)) ++first;
  while (last > first && !kept(last - 1)) --last;
  Ln part = l;
  (Ln::along_y ? part.j : part.i) += first;
  part.n = last - first;
  return part;
}

// The solid cut-off (solid_cutoff.hpp) on line l of the advanced phi and Bt, once the line
// of all seven is written: the same selects as reset_solid_debris, while the line is in
// cache.
template <class Ln>
void reset_line(const Field& phi, const Field& phi_new, std::array<Field, 6>& b, double cutoff, const Ln& l) {
  Field &b0 = b[0], &b1 = b[1], &b2 = b[2], &b3 = b[3], &b4 = b[4], &b5 = b[5];
  along(l, [&](int, int i, int j, int k) { reset_normal_at(phi, phi_new, b0, b1, b2, cutoff, i, j, k); });
  along(l, [&](int, int i, int j, int k) { reset_shear_at<0, 1>(phi, b3, cutoff, i, j, k); });
  along(l, [&](int, int i, int j, int k) { reset_shear_at<0, 2>(phi, b4, cutoff, i, j, k); });
  along(l, [&](int, int i, int j, int k) { reset_shear_at<1, 2>(phi, b5, cutoff, i, j, k); });
}

template <class Store>
void transport(const FieldSet& s, const Store& store, Field& dphidt, std::array<Field, 6>& dBdt, const Box& cells,
               double solid_cutoff) {
  // The cut-off applies to advanced values, not to rates.
  constexpr bool advances = std::is_same_v<Store, StoreEuler>;
  const bool cut = advances && solid_cutoff > 0.0;
  if (lines_along_y(cells)) {  // a thin shell box: lines along y cross the wall rows
    phi_transport(s, store, dphidt, cells);
    transport_component<0, 0>(s, store, dBdt[0], cells);
    transport_component<1, 1>(s, store, dBdt[1], cells);
    transport_component<2, 2>(s, store, dBdt[2], cells);
    transport_component<0, 1>(s, store, dBdt[3], cells);
    transport_component<0, 2>(s, store, dBdt[4], cells);
    transport_component<1, 2>(s, store, dBdt[5], cells);
    if (cut) reset_solid_debris(s.phi(), dphidt, dBdt, solid_cutoff, cells);
    return;
  }
  // All seven fields line by line: the rows of v and Bt a line reads serve every field
  // while they are in cache (field by field, each whole pass brought them again from memory).
  const Inv inv(s.domain());
  const int wall_lo = s.decomp().wall_row_below(), wall_hi = s.decomp().wall_row_above();
  // Points of a Bt component that the solid cut-off resets after the update
  // (reset_line) need no tendency: it is never used there.  Each component runs on
  // the part of the line between its first and last kept point (none: skipped), so the
  // state is bitwise the same and the debris far from the particles costs nothing.
  const Field& phi = s.phi();
  for_lines<2>(cells, [&](const auto& l, double* adv) {
    // Lines run along x here: a line is one row j.
    const bool wall = l.j == wall_lo || l.j == wall_hi;
    phi_line(s, inv, store, dphidt, l, adv);
    if (const auto c = kept_part<Stagger::cell>(phi, solid_cutoff, l); c.n > 0) {
      component_line<0, 0>(s, inv, store, dBdt[0], c, false, adv);
      component_line<1, 1>(s, inv, store, dBdt[1], c, false, adv);
      component_line<2, 2>(s, inv, store, dBdt[2], c, false, adv);
    }
    if (const auto e = kept_part<Stagger::edge_xy>(phi, solid_cutoff, l); e.n > 0)
      component_line<0, 1>(s, inv, store, dBdt[3], e, wall, adv);
    if (const auto e = kept_part<Stagger::edge_xz>(phi, solid_cutoff, l); e.n > 0)
      component_line<0, 2>(s, inv, store, dBdt[4], e, false, adv);
    if (const auto e = kept_part<Stagger::edge_yz>(phi, solid_cutoff, l); e.n > 0)
      component_line<1, 2>(s, inv, store, dBdt[5], e, wall, adv);
    if (cut) reset_line(phi, dphidt, dBdt, solid_cutoff, l);
  });
  // The owned top wall faces of the components staggered in y, beyond `cells`.
  const Box top3 = owned_top_face(dBdt[3], cells), top5 = owned_top_face(dBdt[5], cells);
  transport_component<0, 1>(s, store, dBdt[3], top3);
  transport_component<1, 2>(s, store, dBdt[5], top5);
  if (cut) {
    reset_shear_debris<0, 1>(phi, dBdt[3], solid_cutoff, top3);
    reset_shear_debris<1, 2>(phi, dBdt[5], solid_cutoff, top5);
  }
}

}  // namespace

void transport_tendency(const FieldSet& s, Field& dphidt, std::array<Field, 6>& dBdt, const Box& cells,
                        double solid_cutoff, const RateOutput& out) {
  if (cells.empty()) return;
  with_store(out, [&](const auto& store) { transport(s, store, dphidt, dBdt, cells, solid_cutoff); });
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
  const Inv inv(s.domain());
  const double two_mu = 2.0 * ph.mu, G = ph.G;
  const Box owned{{0, 0, 0}, s.decomp().local()};
  // All six components line by line: the rows of v and Bt a line reads serve every
  // component while they are in cache (component by component, each whole pass brought
  // them again from memory).
  for_lines<3>(owned, [&](const auto& l, double* uc) {
    stretched_normal_line(s, inv, two_mu, G, dt, base, root, tau, l, uc);
    stretched_shear_line<0, 1>(s, inv, two_mu, G, dt, base[3], root, tau[3], l, uc);
    stretched_shear_line<0, 2>(s, inv, two_mu, G, dt, base[4], root, tau[4], l, uc);
    stretched_shear_line<1, 2>(s, inv, two_mu, G, dt, base[5], root, tau[5], l, uc);
  });
  // The top wall faces of the components staggered in y, owned on the top rank.
  for_lines<1>(owned_top_face(tau[3], owned), [&](const auto& l, double* uc) {
    stretched_shear_line<0, 1>(s, inv, two_mu, G, dt, base[3], root, tau[3], l, uc);
  });
  for_lines<1>(owned_top_face(tau[5], owned), [&](const auto& l, double* uc) {
    stretched_shear_line<1, 2>(s, inv, two_mu, G, dt, base[5], root, tau[5], l, uc);
  });
}

}  // namespace efsi
