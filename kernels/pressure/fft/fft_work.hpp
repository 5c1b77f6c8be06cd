#pragma once
// The work of the FFT Poisson solve per owned cell, counted under the conventions of work_count.hpp.
#include <cmath>

#include "work_count.hpp"

namespace efsi {

// FftPoisson::solve on NX x NY x NZ global cells (fft_poisson.cpp):
//   bytes: passes over the field, one read and one write of 8 B per cell each (the half
//   spectrum of NX/2 + 1 complex values taken as NX doubles): forward copy in 1, three
//   transposes (pack, unpack) 6, r2c along x 1, c2c along z 1 = 9; Thomas 1; backward 9
//   (the same, copy out last): 19 passes x 16 B = 304 B (MPI's own copies not counted).
//   flops: the usual FFT counts, 2.5 N log2 N for a real transform of N points and
//   5 N log2 N for a complex one: forward and backward x (2 x 2.5 log2 NX per cell) and z
//   (2 x 5 log2 NZ per complex point, (NX/2 + 1)/NX of them per cell); Thomas per complex
//   unknown: forward row (bj 2, m 2, cp 1, dp = (r scale - a dp)/m 8) 13, back 4: 17.
inline PerCell fft_solve_cost(int NX, int NZ) {
  const double half = (NX / 2 + 1) / static_cast<double>(NX);
  return {304, 2 * 2.5 * std::log2(NX) + half * (2 * 5 * std::log2(NZ) + 17)};
}

}  // namespace efsi
