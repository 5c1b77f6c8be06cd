#pragma once
// Where staggered quantities live and how they are moved: averaging from one location to
// another and first differences. docs/numerics.md, "Staggered grid": a product of quantities that live in
// different places is formed by averaging each factor to the target location.
#include "field.hpp"

namespace efsi {

// Location of tensor component (a, b): diagonal at cell centres, off-diagonal on edges.
constexpr Stagger tensor_location(int a, int b) {
  if (a == b) return Stagger::cell;
  const int lo = a < b ? a : b, hi = a < b ? b : a;
  if (lo == X && hi == Y) return Stagger::edge_xy;
  if (lo == X && hi == Z) return Stagger::edge_xz;
  return Stagger::edge_yz;
}

constexpr Stagger face_location(int a) {
  return a == X ? Stagger::face_x : a == Y ? Stagger::face_y : Stagger::face_z;
}

// Location of d v_a / d x_m: v_a's location with axis m toggled.
constexpr Stagger gradient_location(int a, int m) { return tensor_location(a, m); }

// Per axis: first offset and number of points averaged when moving from S to T.
// A staggered point i lies at the low face of cell i, so the centre i averages faces i and
// i + 1, and the face i averages centres i - 1 and i.
constexpr int avg_first(bool from_staggered, bool to_staggered) {
  return (!from_staggered && to_staggered) ? -1 : 0;
}
constexpr int avg_count(bool from_staggered, bool to_staggered) {
  return from_staggered != to_staggered ? 2 : 1;
}

// Average of g (a value at location S for each index) at location T, index (i, j, k).
template <Stagger S, Stagger T, class G>
inline double average(const G& g, int i, int j, int k) {
  constexpr int ox = avg_first(is_staggered(S, X), is_staggered(T, X));
  constexpr int oy = avg_first(is_staggered(S, Y), is_staggered(T, Y));
  constexpr int oz = avg_first(is_staggered(S, Z), is_staggered(T, Z));
  constexpr int nx = avg_count(is_staggered(S, X), is_staggered(T, X));
  constexpr int ny = avg_count(is_staggered(S, Y), is_staggered(T, Y));
  constexpr int nz = avg_count(is_staggered(S, Z), is_staggered(T, Z));
  // The sum starts from the first sample, not from 0 (0 + x costs an add that the
  // compiler may not drop: it turns -0 into +0); fully unrolled, so that the caller's loop
  // over i stays a single loop the compiler can vectorise.
  constexpr int count = nx * ny * nz;
  double s = g(i + ox, j + oy, k + oz);
#pragma GCC unroll 8
  for (int m = 1; m < count; ++m) s += g(i + ox + m % nx, j + oy + (m / nx) % ny, k + oz + m / (nx * ny));
  return s * (1.0 / count);
}

template <Stagger S, Stagger T>
inline double average(const Field& f, int i, int j, int k) {
  return average<S, T>([&f](int a, int b, int c) { return f(a, b, c); }, i, j, k);
}

inline constexpr int unit(int axis, int a) { return axis == a ? 1 : 0; }

// d f / d x_m of a field at location S, evaluated at S with axis m toggled, index (i,j,k).
template <Stagger S, int M>
inline double difference(const Field& f, int i, int j, int k, double inv_h) {
  constexpr int dx = unit(M, X), dy = unit(M, Y), dz = unit(M, Z);
  if constexpr (is_staggered(S, M))  // faces i, i + 1 around the centre i
    return (f(i + dx, j + dy, k + dz) - f(i, j, k)) * inv_h;
  else  // centres i - 1, i around the face i
    return (f(i, j, k) - f(i - dx, j - dy, k - dz)) * inv_h;
}

}  // namespace efsi
