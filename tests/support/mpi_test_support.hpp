#pragma once
// Small pieces every MPI test uses: the world's rank and size, the message of an expected
// ConfigError, and the decompositions a rank count can make of a grid.
#include <mpi.h>

#include <string>
#include <vector>

#include "config_error.hpp"
#include "grid_types.hpp"

namespace efsi::testing {

inline int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

inline int world_size() {
  int p = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &p);
  return p;
}

// Runs f, which must throw ConfigError, and returns its message.
template <class F>
std::string config_error_of(F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "<no ConfigError thrown>";
}

// Every PX x PY x PZ = p that divides the grid into blocks of at least `min_block` cells,
// in the order px, then py ascending.
inline std::vector<Int3> fitting_decompositions(int p, const Int3& grid, int min_block) {
  std::vector<Int3> out;
  for (int px = 1; px <= p; ++px)
    for (int py = 1; py <= p / px; ++py) {
      if (p % (px * py) != 0) continue;
      const Int3 d{px, py, p / (px * py)};
      bool fits = true;
      for (int a = 0; a < 3; ++a) fits = fits && grid[a] % d[a] == 0 && grid[a] / d[a] >= min_block;
      if (fits) out.push_back(d);
    }
  return out;
}

}  // namespace efsi::testing
