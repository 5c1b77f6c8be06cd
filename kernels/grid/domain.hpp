#pragma once
// The physical box: cells per axis and lengths. Walls at y = 0 and y = length[Y];
// periodic in x and z. Uniform spacing per axis (cubic cells in every paper case).
#include <array>

#include "grid_types.hpp"

namespace efsi {

struct Domain {
  Int3 cells{64, 64, 64};
  std::array<double, 3> length{3.6, 3.6, 3.6};

  double spacing(int axis) const { return length[axis] / cells[axis]; }
  double cell_volume() const { return spacing(X) * spacing(Y) * spacing(Z); }
};

}  // namespace efsi
