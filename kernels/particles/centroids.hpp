#pragma once
// Particle centroids (docs/numerics.md, "Particles"): connected regions of cells with phi > 1/2,
// 6-connected, over the whole domain, across ranks and across the periodic x and z
// boundaries, each with its volume and its true (unwrapped) centroid.
//
// Parallel without gathering the field: each rank labels its block (union-find that also
// records how many periodic images a step crosses), the boundary planes of labels go to
// the face neighbours, and only the small graph of local pieces and their contacts goes
// to rank 0, which joins the pieces and broadcasts the regions.
#include <array>
#include <cstdint>
#include <vector>

#include "decomposition.hpp"
#include "domain.hpp"
#include "field.hpp"

namespace efsi {

// Named SolidRegion because efsi::Region is the timer-region enum of region_timers.hpp.
struct SolidRegion {
  double volume;                    // sum of phi * cell volume over the region's cells
  std::array<double, 3> centroid;   // phi-weighted mean of cell centres, in the box [0, L)
  std::int64_t cells;               // cells with phi > 1/2 in the region
  std::int64_t first_cell;          // lowest global index i + Nx (j + Ny k) among them: the sort key
  // Joined to its own periodic image along this axis (a slab through the whole channel):
  // the centroid along it is then the plain mean of in-box positions, since no
  // unwrapping can be right.
  std::array<bool, 3> wraps;
};

// Collective over decomp.comm().  Every rank returns the same list, sorted by first_cell,
// which does not depend on the decomposition.  Volumes and centroids agree across
// decompositions to round-off (the sums run in a different order).
std::vector<SolidRegion> solid_regions(const Field& phi, const Domain& domain, const CartDecomposition& decomp);

}  // namespace efsi
