#include "decomposition.hpp"

#include <limits>
#include <string>

#include "config_error.hpp"

namespace efsi {
namespace {

const char* const kAxisName[3] = {"x", "y", "z"};

// Empty when dims fits the grid, otherwise the reason it does not.
std::string misfit(const Int3& dims, const Int3& global, int min_block) {
  for (int a = 0; a < 3; ++a) {
    if (global[a] % dims[a] != 0)
      return std::string("N") + kAxisName[a] + "=" + std::to_string(global[a]) +
             " is not a multiple of P" + kAxisName[a] + "=" + std::to_string(dims[a]);
  }
  for (int a = 0; a < 3; ++a) {
    const int n = global[a] / dims[a];
    if (n < min_block)
      return std::string("local block is ") + std::to_string(n) + " cells in " + kAxisName[a] +
             " (N" + kAxisName[a] + "/P" + kAxisName[a] + " = " + std::to_string(global[a]) + "/" +
             std::to_string(dims[a]) + "), thinner than the halo width " + std::to_string(min_block);
  }
  return {};
}

// Cells on the faces a rank exchanges, per rank; smaller is less communication.
double halo_surface(const Int3& dims, const Int3& global) {
  const double n[3] = {double(global[0]) / dims[0], double(global[1]) / dims[1],
                       double(global[2]) / dims[2]};
  double s = 0;
  if (dims[0] > 1) s += n[1] * n[2];
  if (dims[1] > 1) s += n[0] * n[2];
  if (dims[2] > 1) s += n[0] * n[1];
  return s;
}

}  // namespace

Int3 choose_dims(int ranks, const Int3& global, int min_block, const Int3& forced) {
  for (int a = 0; a < 3; ++a) {
    if (global[a] < 1)
      throw ConfigError(std::string("grid size N") + kAxisName[a] + "=" + std::to_string(global[a]) +
                        " must be at least 1");
    if (forced[a] < 0)
      throw ConfigError(std::string("forced P") + kAxisName[a] + "=" + std::to_string(forced[a]) +
                        " must be positive (0 lets the library choose)");
  }
  int fixed = 1;
  bool all_forced = true;
  for (int a = 0; a < 3; ++a) {
    if (forced[a] > 0) fixed *= forced[a];
    else all_forced = false;
  }
  if (ranks % fixed != 0 || (all_forced && fixed != ranks))
    throw ConfigError("forced decomposition " + std::to_string(forced[0]) + "x" +
                      std::to_string(forced[1]) + "x" + std::to_string(forced[2]) + " needs " +
                      (all_forced ? std::to_string(fixed) : "a multiple of " + std::to_string(fixed)) +
                      " ranks but " + std::to_string(ranks) + " were started (0 = free)");

  Int3 dims = forced;
  MPI_Dims_create(ranks, 3, dims.data());
  const std::string first = misfit(dims, global, min_block);
  if (first.empty()) return dims;

  Int3 best{0, 0, 0};
  double best_surface = std::numeric_limits<double>::infinity();
  for (int px = 1; px <= ranks; ++px) {
    if (ranks % px || (forced[0] > 0 && px != forced[0])) continue;
    for (int py = 1; py <= ranks / px; ++py) {
      if ((ranks / px) % py || (forced[1] > 0 && py != forced[1])) continue;
      const int pz = ranks / px / py;
      if (forced[2] > 0 && pz != forced[2]) continue;
      const Int3 d{px, py, pz};
      if (!misfit(d, global, min_block).empty()) continue;
      const double s = halo_surface(d, global);
      if (s < best_surface) best_surface = s, best = d;
    }
  }
  if (best[0] == 0) {
    if (all_forced)
      throw ConfigError("decomposition " + to_string(dims) + " does not fit grid " + to_string(global) +
                        ": " + first);
    throw ConfigError("no decomposition of " + std::to_string(ranks) + " ranks fits grid " +
                      to_string(global) + " (e.g. " + to_string(dims) + ": " + first + ")");
  }
  return best;
}

CartDecomposition::CartDecomposition(MPI_Comm comm, const Int3& global_cells, int min_block,
                                     const Int3& forced)
    : global_(global_cells) {
  int ranks = 0;
  MPI_Comm_size(comm, &ranks);
  dims_ = choose_dims(ranks, global_cells, min_block, forced);

  const int periodic[3] = {1, 0, 1};
  // reorder = 0 keeps rank numbers, so results do not depend on the MPI library's placement.
  MPI_Cart_create(comm, 3, dims_.data(), periodic, 0, &cart_);
  MPI_Comm_rank(cart_, &rank_);
  MPI_Comm_size(cart_, &size_);
  MPI_Cart_coords(cart_, rank_, 3, coords_.data());
  for (int a = 0; a < 3; ++a) {
    local_[a] = global_[a] / dims_[a];
    offset_[a] = coords_[a] * local_[a];
  }
}

CartDecomposition::~CartDecomposition() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (cart_ != MPI_COMM_NULL && !finalized) MPI_Comm_free(&cart_);
}

int CartDecomposition::neighbour(const Int3& step) const {
  Int3 c = coords_;
  for (int a = 0; a < 3; ++a) c[a] += step[a];
  if (c[Y] < 0 || c[Y] >= dims_[Y]) return MPI_PROC_NULL;
  int r = MPI_PROC_NULL;
  MPI_Cart_rank(cart_, c.data(), &r);  // wraps the periodic axes
  return r;
}

}  // namespace efsi
