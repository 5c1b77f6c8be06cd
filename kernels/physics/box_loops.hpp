#pragma once
// The loops the physics kernels run over a box of output points: OpenMP over lines of
// points, each line one vectorised loop, and the split at the wall rows that keeps the wall
// test out of the lines.
//
// A line runs along x, the unit stride, except in a box too thin in x for a vector (the x
// faces of the shell the asynchronous step does last: 1 to 3 points in x, the whole block
// in y): there it runs along y, a strided vector loop, instead of thousands of scalar
// remainders.  Each point's arithmetic is the same either way.
#include <cstddef>
#include <vector>

#include "grid_types.hpp"

namespace efsi {

// Below this many points in x a box runs its lines along y (when it is longer in y).
inline constexpr int kShortRow = 8;

inline bool lines_along_y(const Box& b) {
  const int nx = b.hi[X] - b.lo[X], ny = b.hi[Y] - b.lo[Y];
  return nx < kShortRow && ny > nx;
}

// n points from (i, j, k) along y (AlongY) or x.  The direction is a type, so that a line
// body is compiled once per direction with one call of each stencil in each loop (GCC
// inlines those; a run-time choice between two loops leaves the stencils out of line).
template <bool AlongY>
struct Line {
  static constexpr bool along_y = AlongY;
  int i, j, k, n;
};

// f(i, j, k) for every point of `b`.  Every kernel writes one output array that none of its
// inputs alias; without `omp simd` GCC gives up on the run-time alias checks and leaves the
// stencils scalar.  flatten: the body is inlined into both loops (with two call sites GCC
// would otherwise call it, and the loops would stay scalar).
template <class F>
[[gnu::flatten]] void for_box(const Box& b, F&& f) {
  if (b.empty()) return;
  if (!lines_along_y(b)) {
#pragma omp parallel for collapse(2) schedule(static)
    for (int k = b.lo[Z]; k < b.hi[Z]; ++k)
      for (int j = b.lo[Y]; j < b.hi[Y]; ++j)
#pragma omp simd
        for (int i = b.lo[X]; i < b.hi[X]; ++i) f(i, j, k);
  } else {
#pragma omp parallel for collapse(2) schedule(static)
    for (int k = b.lo[Z]; k < b.hi[Z]; ++k)
      for (int i = b.lo[X]; i < b.hi[X]; ++i)
#pragma omp simd
        for (int j = b.lo[Y]; j < b.hi[Y]; ++j) f(i, j, k);
  }
}

// for_box's loops on the calling thread alone, for a caller that already is one thread's
// share of a parallel region.
template <class F>
[[gnu::flatten]] void for_box_serial(const Box& b, F&& f) {
  if (b.empty()) return;
  if (!lines_along_y(b)) {
    for (int k = b.lo[Z]; k < b.hi[Z]; ++k)
      for (int j = b.lo[Y]; j < b.hi[Y]; ++j)
#pragma omp simd
        for (int i = b.lo[X]; i < b.hi[X]; ++i) f(i, j, k);
  } else {
    for (int k = b.lo[Z]; k < b.hi[Z]; ++k)
      for (int i = b.lo[X]; i < b.hi[X]; ++i)
#pragma omp simd
        for (int j = b.lo[Y]; j < b.hi[Y]; ++j) f(i, j, k);
  }
}

// for_box, or for_box_serial when Serial.
template <bool Serial, class F>
void for_box_as(const Box& b, F&& f) {
  if constexpr (Serial) for_box_serial(b, f);
  else for_box(b, f);
}

// Calls g(piece, is_wall_row) for the pieces of `b` split at the wall rows j = wall_lo and
// j = wall_hi, so that no loop carries the wall test.
template <class G>
void split_wall_rows(const Box& b, int wall_lo, int wall_hi, G&& g) {
  for (int j = b.lo[Y]; j < b.hi[Y];) {
    const bool wall = j == wall_lo || j == wall_hi;
    int e = j + 1;
    if (!wall)
      while (e < b.hi[Y] && e != wall_lo && e != wall_hi) ++e;
    Box piece = b;
    piece.lo[Y] = j;
    piece.hi[Y] = e;
    g(piece, wall);
    j = e;
  }
}

// Calls line(l, scratch) for every line of `b` (a generic lambda: it is instantiated for
// both directions), OpenMP over the lines with a static split, `scratch` pointing at
// `Buffers` arrays of the line's length private to the thread.  A kernel too large for one
// vectorised loop runs a few loops along each line instead (a loop per stencil keeps every
// stencil inline and in registers), passing partial sums through the scratch arrays in the
// order one loop would have added them.
template <int Buffers, class L>
void for_lines(const Box& b, L&& line) {
  if (b.empty()) return;
  const bool y = lines_along_y(b);
  const int n = y ? b.hi[Y] - b.lo[Y] : b.hi[X] - b.lo[X];
#pragma omp parallel
  {
    std::vector<double> scratch(Buffers * static_cast<std::size_t>(n));
    if (y) {
#pragma omp for collapse(2) schedule(static)
      for (int k = b.lo[Z]; k < b.hi[Z]; ++k)
        for (int i = b.lo[X]; i < b.hi[X]; ++i) line(Line<true>{i, b.lo[Y], k, n}, scratch.data());
    } else {
#pragma omp for collapse(2) schedule(static)
      for (int k = b.lo[Z]; k < b.hi[Z]; ++k)
        for (int j = b.lo[Y]; j < b.hi[Y]; ++j) line(Line<false>{b.lo[X], j, k, n}, scratch.data());
    }
  }
}

// f(t, i, j, k) for the points t = 0 .. n-1 of the line, vectorised, f inlined.
template <class F>
[[gnu::flatten]] inline void along(const Line<false>& l, F&& f) {
#pragma omp simd
  for (int t = 0; t < l.n; ++t) f(t, l.i + t, l.j, l.k);
}
template <class F>
[[gnu::flatten]] inline void along(const Line<true>& l, F&& f) {
#pragma omp simd
  for (int t = 0; t < l.n; ++t) f(t, l.i, l.j + t, l.k);
}

}  // namespace efsi
