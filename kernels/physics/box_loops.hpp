#pragma once
// The loops the physics kernels run over a box of output points: OpenMP over rows, the row
// as one vectorised loop, and the split at the wall rows that keeps the wall test out of it.
#include <cstddef>
#include <vector>

#include "grid_types.hpp"

namespace efsi {

template <class F>
void for_box(const Box& b, F&& f) {
  if (b.empty()) return;
#pragma omp parallel for collapse(2) schedule(static)
  for (int k = b.lo[Z]; k < b.hi[Z]; ++k)
    for (int j = b.lo[Y]; j < b.hi[Y]; ++j)
      // Every kernel writes one output array that none of its inputs alias; without this
      // GCC gives up on the run-time alias checks and leaves the stencils scalar.
#pragma omp simd
      for (int i = b.lo[X]; i < b.hi[X]; ++i) f(i, j, k);
}

// Calls g(piece, is_wall_row) for the pieces of `b` split at the wall rows j = wall_lo and
// j = wall_hi, so that no loop over i carries the wall test.
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

// Calls row(j, k, scratch) for every row of `b`, OpenMP over the rows with for_box's static
// split, `scratch` pointing at `Buffers` rows of the box's length private to the thread.  A
// kernel too large for one vectorised loop runs a few loops along each row instead (a loop
// per stencil keeps every stencil inline and in registers), passing partial sums through
// the scratch rows in the order one loop would have added them.
template <int Buffers, class R>
void for_rows(const Box& b, R&& row) {
  if (b.empty()) return;
  const std::size_t n = static_cast<std::size_t>(b.hi[X] - b.lo[X]);
#pragma omp parallel
  {
    std::vector<double> scratch(Buffers * n);
#pragma omp for collapse(2) schedule(static)
    for (int k = b.lo[Z]; k < b.hi[Z]; ++k)
      for (int j = b.lo[Y]; j < b.hi[Y]; ++j) row(j, k, scratch.data());
  }
}

// f(i) along one row of `b`, vectorised (see for_box on the aliasing).
template <class F>
inline void along_row(const Box& b, F&& f) {
#pragma omp simd
  for (int i = b.lo[X]; i < b.hi[X]; ++i) f(i);
}

}  // namespace efsi
