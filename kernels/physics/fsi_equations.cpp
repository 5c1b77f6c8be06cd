#include "fsi_equations.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>

#include <omp.h>

#include "box_loops.hpp"
#include "constitutive.hpp"
#include "mul_add.hpp"

namespace efsi {
namespace {

using Inv = InverseSpacing;

// tau_AB at (i, j, k) of its location.
template <int A, int B, class Root>
inline double stress_at(const FieldSet& s, const Inv& inv, double two_mu, double G, const Root& r, int i, int j,
                        int k) {
  return two_mu * strain_rate<A, B>(s, inv, i, j, k) + G * solid_stress_over_G<A, B>(s, r, i, j, k);
}

// The three components at one location in one loop: the rows of v, sqrt(phi) and Bt a
// point reads serve all three while they are in cache (component by component, each pass
// brought them from memory again).
template <int A0, int B0, int A1, int B1, int A2, int B2, bool Serial = false, class Out>
void stress_components(const FieldSet& s, const Physics& ph, const Field& root, Out& t0, Out& t1, Out& t2,
                       const Box& box) {
  const Inv inv(s.domain());
  const double two_mu = 2.0 * ph.mu, G = ph.G;
  const auto r = [&root](int a, int b, int c) { return root(a, b, c); };
  for_box_as<Serial>(box, [&](int i, int j, int k) {
    t0(i, j, k) = stress_at<A0, B0>(s, inv, two_mu, G, r, i, j, k);
    t1(i, j, k) = stress_at<A1, B1>(s, inv, two_mu, G, r, i, j, k);
    t2(i, j, k) = stress_at<A2, B2>(s, inv, two_mu, G, r, i, j, k);
  });
}

// root = sqrt_phi(phi) on the centres that the stress at `centres` and `edges` reads (an edge
// averages the centres below it along its two staggered axes).
void solid_root(const Field& phi, Field& root, const Box& centres, const Box& edges) {
  Box b = centres;
  if (b.empty()) b = edges;
  for (int a = 0; a < 3; ++a) {
    if (!edges.empty()) {
      b.lo[a] = std::min(b.lo[a], edges.lo[a] - 1);
      b.hi[a] = std::max(b.hi[a], edges.hi[a]);
    }
  }
  for_box(b, [&](int i, int j, int k) { root(i, j, k) = sqrt_phi(phi(i, j, k)); });
}

// Transport velocity v_A (a face quantity) at the edge or centre `E` of the flux through
// the face of component C along axis A, for the skew-symmetric advection.
template <int C, int A>
inline double flux_velocity(const FieldSet& s, int i, int j, int k) {
  const Field& ua = s.vel(A);
  if constexpr (A == C) {  // at the centre i: mean of faces i and i + 1
    constexpr int dx = unit(A, X), dy = unit(A, Y), dz = unit(A, Z);
    return 0.5 * (ua(i, j, k) + ua(i + dx, j + dy, k + dz));
  } else {  // at the edge i between faces of C: mean of v_A over the C direction
    constexpr int cx = unit(C, X), cy = unit(C, Y), cz = unit(C, Z);
    return 0.5 * (ua(i - cx, j - cy, k - cz) + ua(i, j, k));
  }
}

template <int C, int A>
inline double advection_term(const FieldSet& s, const Inv& inv, int i, int j, int k) {
  constexpr int ax = unit(A, X), ay = unit(A, Y), az = unit(A, Z);
  const Field& uc = s.vel(C);
  // Centres of flux above and below: for A == C the centres i and i - 1, otherwise the
  // edges i + 1 and i along A.
  double up, lo;
  if constexpr (A == C) {
    up = flux_velocity<C, A>(s, i, j, k);
    lo = flux_velocity<C, A>(s, i - ax, j - ay, k - az);
  } else {
    up = flux_velocity<C, A>(s, i + ax, j + ay, k + az);
    lo = flux_velocity<C, A>(s, i, j, k);
  }
  // Half the divergence form plus half the advective form collapses to this.
  return 0.5 * inv.h[A] * (up * uc(i + ax, j + ay, k + az) - lo * uc(i - ax, j - ay, k - az));
}

template <int C, int A, class Tau>
inline double stress_divergence_term(const Tau& tau, const Inv& inv, int i, int j, int k) {
  constexpr int ax = unit(A, X), ay = unit(A, Y), az = unit(A, Z);
  const auto& t = tau[tensor_index(C, A)];
  if constexpr (A == C)  // centres i - 1 and i around the face i
    return (t(i, j, k) - t(i - ax, j - ay, k - az)) * inv.h[A];
  else  // edges i and i + 1 along A
    return (t(i + ax, j + ay, k + az) - t(i, j, k)) * inv.h[A];
}

// Sets out[C] to body(C, i, j, k) on the faces of the three components in `box` in one
// loop, and out[Y] to wall(i, j, k) on the wall faces of v (global j = 0 and j = NY; the
// default: zero).  The rows of the fields a face reads serve all three components while
// they are in cache (component by component, each pass brought them from memory again).
// C is a std::integral_constant.
struct ZeroAt {
  double operator()(int, int, int) const { return 0.0; }
};
template <bool Serial = false, class Body, class Wall = ZeroAt>
void faces_of_components(const FieldSet& s, std::array<Field, 3>& out, const Box& box, const Body& body,
                         const Wall& wall_value = {}) {
  using CX = std::integral_constant<int, X>;
  using CY = std::integral_constant<int, Y>;
  using CZ = std::integral_constant<int, Z>;
  Field &o0 = out[0], &o1 = out[1], &o2 = out[2];
  const int wall_lo = s.decomp().wall_row_below(), wall_hi = s.decomp().wall_row_above();
  split_wall_rows(box, wall_lo, wall_hi, [&](const Box& b, bool wall) {
    if (wall) {
      for_box_as<Serial>(b, [&](int i, int j, int k) {
        o0(i, j, k) = body(CX{}, i, j, k);
        o1(i, j, k) = wall_value(i, j, k);
        o2(i, j, k) = body(CZ{}, i, j, k);
      });
    } else {
      for_box_as<Serial>(b, [&](int i, int j, int k) {
        o0(i, j, k) = body(CX{}, i, j, k);
        o1(i, j, k) = body(CY{}, i, j, k);
        o2(i, j, k) = body(CZ{}, i, j, k);
      });
    }
  });
}

template <int C, class Tau>
inline double divergence_of(const Tau& tau, const Inv& inv, int i, int j, int k) {
  return stress_divergence_term<C, X>(tau, inv, i, j, k) + stress_divergence_term<C, Y>(tau, inv, i, j, k) +
         stress_divergence_term<C, Z>(tau, inv, i, j, k);
}

// dv_C/dt at the face (i, j, k) of component C.
template <int C, class Tau>
inline double momentum_rate(const FieldSet& s, const Inv& inv, const Tau& tau, double inv_rho, double force, int i,
                            int j, int k) {
  constexpr int cx = unit(C, X), cy = unit(C, Y), cz = unit(C, Z);
  const Field& p = s.p();
  const double adv = advection_term<C, X>(s, inv, i, j, k) + advection_term<C, Y>(s, inv, i, j, k) +
                     advection_term<C, Z>(s, inv, i, j, k);
  const double grad_p = (p(i, j, k) - p(i - cx, j - cy, k - cz)) * inv.h[C];
  return -adv + (divergence_of<C>(tau, inv, i, j, k) - grad_p) * inv_rho + (C == X ? force : 0.0);
}

}  // namespace

FsiWork::FsiWork(const CartDecomposition& decomp)
    : tau{Field(decomp, {"tau11", Stagger::cell, 1}), Field(decomp, {"tau22", Stagger::cell, 1}),
          Field(decomp, {"tau33", Stagger::cell, 1}), Field(decomp, {"tau12", Stagger::edge_xy, 1}),
          Field(decomp, {"tau13", Stagger::edge_xz, 1}), Field(decomp, {"tau23", Stagger::edge_yz, 1})},
      vstar{Field(decomp, {"u*", Stagger::face_x, 1, WallParity::odd}),
            Field(decomp, {"v*", Stagger::face_y, 1, WallParity::odd}),
            Field(decomp, {"w*", Stagger::face_z, 1, WallParity::odd})},
      phi_new(decomp, fsi_field_specs()[4]),
      B_new{Field(decomp, fsi_field_specs()[5]), Field(decomp, fsi_field_specs()[6]),
            Field(decomp, fsi_field_specs()[7]), Field(decomp, fsi_field_specs()[8]),
            Field(decomp, fsi_field_specs()[9]), Field(decomp, fsi_field_specs()[10])},
      div(decomp, {"div*", Stagger::cell, 1, WallParity::even}),
      dp(decomp, {"dp", Stagger::cell, 1, WallParity::even}),
      root_phi(decomp, {"sqrt_phi", Stagger::cell, 1, WallParity::even}) {}

KernelBoxes full_boxes(const Int3& n) {
  return {{{-1, -1, -1}, n}, {{0, 0, 0}, {n[0] + 1, n[1] + 1, n[2] + 1}}, {{0, 0, 0}, n}, {{0, 0, 0}, n}};
}

KernelBoxes interior_boxes(const Int3& n, const CurrentSides& current) {
  const Int3 m1{n[0] - 1, n[1] - 1, n[2] - 1}, m3{n[0] - 3, n[1] - 3, n[2] - 3};
  const KernelBoxes full = full_boxes(n);
  KernelBoxes in{{{0, 0, 0}, m1}, {{1, 1, 1}, n}, {{1, 1, 1}, m1}, {{3, 3, 3}, m3}};
  for (auto [b, f] : {std::pair{&in.stress_centres, &full.stress_centres}, std::pair{&in.stress_edges, &full.stress_edges},
                      std::pair{&in.momentum, &full.momentum}, std::pair{&in.transport, &full.transport}})
    for (int a = 0; a < 3; ++a) {
      if (current[a][0]) b->lo[a] = f->lo[a];
      if (current[a][1]) b->hi[a] = f->hi[a];
    }
  return in;
}

void compute_stress(const FieldSet& s, const Physics& ph, Field& root, std::array<Field, 6>& tau,
                    const Box& centres, const Box& edges) {
  if (centres.empty() && edges.empty()) return;
  solid_root(s.phi(), root, centres, edges);
  stress_components<0, 0, 1, 1, 2, 2>(s, ph, root, tau[0], tau[1], tau[2], centres);
  stress_components<0, 1, 0, 2, 1, 2>(s, ph, root, tau[3], tau[4], tau[5], edges);
}

// The momentum on the faces of `faces` from any store of tau (Fields, or the planes of a
// TauRing): one definition for both.
template <bool Serial, class Tau>
void momentum_from(const FieldSet& s, const Physics& ph, const Tau& tau, std::array<Field, 3>& dvdt, const Box& faces,
                   const RateOutput& out) {
  const Inv inv(s.domain());
  const double inv_rho = 1.0 / ph.rho, force = ph.force * inv_rho;
  with_store(out, [&](const auto& store) {
    const Field& v = s.vel(Y);
    faces_of_components<Serial>(
        s, dvdt, faces,
        [&](auto c, int i, int j, int k) {
          constexpr int C = decltype(c)::value;
          return store(s.vel(C), i, j, k, momentum_rate<C>(s, inv, tau, inv_rho, force, i, j, k));
        },
        [&](int i, int j, int k) { return store(v, i, j, k, 0.0); });
  });
}

void momentum_tendency(const FieldSet& s, const Physics& ph, const std::array<Field, 6>& tau,
                       std::array<Field, 3>& dvdt, const Box& faces, const RateOutput& out) {
  momentum_from<false>(s, ph, tau, dvdt, faces, out);
}

TauRing::TauRing(const std::array<Field, 6>& layout) {
  std::size_t total = 0;
  for (const Field& f : layout) total += 3 * static_cast<std::size_t>(f.stride_z());
  // Storage: folded in the simulation build, where 8192 ranks' rings (760 KB a rank of 64^3)
  // would otherwise be most of the simulator's private memory.
  data_ = allocate_storage(total, true);
  double* p = data_.get();
  for (int c = 0; c < 6; ++c) {
    const Field& f = layout[c];
    // Field's layout of one plane: the planes' own origin is the field's less its z halo.
    planes_[c] = Planes{p + (f.index(0, 0, 0) - f.stride_z() * f.halo()), f.stride_y(), f.stride_z()};
    p += 3 * f.stride_z();
  }
}

StressAndMomentum::StressAndMomentum(const std::array<Field, 6>& tau_layout) {
  const int threads = std::max(1, omp_get_max_threads());
  rings_.reserve(threads);
  for (int t = 0; t < threads; ++t) rings_.emplace_back(tau_layout);
}

void StressAndMomentum::run(const FieldSet& s, const Physics& ph, Field& root, std::array<Field, 3>& dvdt,
                            const RateOutput& out) {
  const Int3 n = s.decomp().local();
  const KernelBoxes full = full_boxes(n);
  solid_root(s.phi(), root, full.stress_centres, full.stress_edges);
  auto plane = [](Box b, int k) {
    b.lo[Z] = k;
    b.hi[Z] = k + 1;
    return b;
  };
#pragma omp parallel num_threads(static_cast<int>(rings_.size()))
  {
    TauRing& ring = rings_[omp_get_thread_num()];
    const int nt = omp_get_num_threads(), t = omp_get_thread_num();
    const int k0 = static_cast<int>(static_cast<long>(n[Z]) * t / nt);
    const int k1 = static_cast<int>(static_cast<long>(n[Z]) * (t + 1) / nt);
    // The momentum of plane k reads the centres k - 1 and k and the edges k and k + 1.
    auto stress_planes = [&](int centres, int edges) {
      stress_components<0, 0, 1, 1, 2, 2, true>(s, ph, root, ring[0], ring[1], ring[2],
                                                plane(full.stress_centres, centres));
      stress_components<0, 1, 0, 2, 1, 2, true>(s, ph, root, ring[3], ring[4], ring[5], plane(full.stress_edges, edges));
    };
    if (k0 < k1) {
      stress_planes(k0 - 1, k0);
      for (int k = k0; k < k1; ++k) {
        stress_planes(k, k + 1);
        momentum_from<true>(s, ph, ring, dvdt, plane(full.momentum, k), out);
      }
    }
  }
}

Box owned_extent(const Field& q, const Box& cells) {
  Box box = cells;
  if (q.owned_end(Y) > q.n()[Y] && box.hi[Y] == q.n()[Y]) box.hi[Y] = q.owned_end(Y);
  return box;
}

Box owned_top_face(const Field& q, const Box& cells) {
  Box top = owned_extent(q, cells);
  if (top.hi[Y] == cells.hi[Y]) return Box{};
  top.lo[Y] = cells.hi[Y];
  return top;
}

}  // namespace efsi

namespace efsi {

void add_stress_divergence(const FieldSet& s, const std::array<Field, 6>& tau, double c,
                           const std::array<Field, 3>& base, std::array<Field, 3>& out, const Box& faces) {
  const Inv inv(s.domain());
  faces_of_components(s, out, faces, [&](auto m, int i, int j, int k) {
    constexpr int C = decltype(m)::value;
    return mul_add(c, divergence_of<C>(tau, inv, i, j, k), base[C](i, j, k));
  });
}

}  // namespace efsi
