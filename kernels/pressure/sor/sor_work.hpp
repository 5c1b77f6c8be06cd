#pragma once
// The work of the SOR Poisson solve per owned cell, counted under the conventions of work_count.hpp.
#include "work_count.hpp"

namespace efsi {

// One four-colour SOR sweep (SorPoisson::update): each colour is a separate pass (it reads
//   the colours before it) that reads all of x (the neighbours are the other colours),
//   reads rhs on its rows (half of them: 4 B per cell) and writes x on its rows (4 B):
//   16 B per colour, 64 B per sweep.  Per updated point: ax (a + b), wlo a + whi b,
//   az (a + b), factor rhs, 3 adds/subs: 11; keep x + wd s: 3; 14 flops per cell per sweep.
inline constexpr PerCell kSorSweep{64, 14};

// SmacSorPressure::increment's dp.fill(0) before the sweeps: writes dp, 8 B.
inline constexpr PerCell kFill{8, 0};

}  // namespace efsi
