#pragma once
// The work of the SOR Poisson solve per owned cell, counted under the conventions of work_count.hpp.
#include "grid_types.hpp"
#include "work_count.hpp"

namespace efsi {

// Colours 0 and 1 (2 and 3) go in one pass over their rows where x is whole on each rank
// (rank grid 1 x PY x PZ: the row's ends are its own periodic ghosts), and in separate
// passes, each followed by an exchange, where x is split.
inline bool sor_fuses_colour_pairs(const Int3& dims) { return dims[0] == 1; }
inline int sor_passes_per_sweep(const Int3& dims) { return sor_fuses_colour_pairs(dims) ? 2 : 4; }

// One four-colour SOR sweep (SorPoisson::update) in `passes` passes (2 or 4): each pass
//   reads all of x (the neighbours are the other colours), reads rhs on its rows (half of
//   them: 4 B per cell) and writes x on its rows (4 B): 16 B per pass.  Per updated point:
//   ax (a + b), wlo a + whi b, az (a + b), factor rhs, 3 adds/subs: 11; keep x + wd s: 3;
//   14 flops per cell per sweep.
constexpr PerCell sor_sweep_cost(int passes) { return {16.0 * passes, 14}; }

// SmacSorPressure::increment's dp.fill(0) before the sweeps: writes dp, 8 B.
inline constexpr PerCell kFill{8, 0};

}  // namespace efsi
