#pragma once
// The work of ACM's pressure increment per owned cell, counted under the conventions of work_count.hpp.
#include "work_count.hpp"

namespace efsi {

// acm_moments, the local sums before the one MPI_Allreduce of 7 doubles: reads div and p:
//   16 B; two 7-point Laplacians ((a - 2c + b) h^-2: 4 per axis, 2 adds: 14 each) 28,
//   five products accumulated (2 each) 10, two sums 2: 40 flops.
inline constexpr PerCell kAcmMoments{16, 40};

// AcmPressure::increment = acm_moments + the update dp = -(b p + a div)/dt - shift:
//   the update reads p, div, writes dp: 24 B; 2 mul, add, div, sub: 5 flops.
inline constexpr PerCell kAcmUpdate{24, 5};

}  // namespace efsi
