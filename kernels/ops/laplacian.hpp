#pragma once
// The 7-point Laplacian of the pressure equations (docs/numerics.md, "the discrete
// Poisson equation"), shared by ACM's moments and the SOR residual.
#include "field.hpp"

namespace efsi {

// At cell (i, j, k); walls: zero flux through the even-mirrored ghosts.
inline double laplacian(const Field& f, const double inv_h2[3], int i, int j, int k) {
  const double c = f(i, j, k);
  return (f(i + 1, j, k) - 2 * c + f(i - 1, j, k)) * inv_h2[0] + (f(i, j + 1, k) - 2 * c + f(i, j - 1, k)) * inv_h2[1] +
         (f(i, j, k + 1) - 2 * c + f(i, j, k - 1)) * inv_h2[2];
}

}  // namespace efsi
