#include "decomposition.hpp"

#include <algorithm>
#include <array>
#include <functional>
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

// Axis a gets factor p[a] of the factors sorted largest first.  Tried in this order, so that
// a tie goes to the earlier: the largest factor on y, then on z, x last (halo_cost).
constexpr std::array<Int3, 6> kPermutations{{{2, 0, 1}, {1, 0, 2}, {2, 1, 0}, {1, 2, 0}, {0, 2, 1}, {0, 1, 2}}};

bool keeps(const Int3& d, const Int3& forced) {
  for (int a = 0; a < 3; ++a)
    if (forced[a] > 0 && d[a] != forced[a]) return false;
  return true;
}

// The permutation of `factors` that keeps `forced` and costs the least (halo_cost) of those
// `fits` accepts, for blocks block_of(d); {0, 0, 0} when none is accepted.
template <class Fits, class BlockOf>
Int3 cheapest_permutation(const Int3& factors, const Int3& forced, Fits fits, BlockOf block_of) {
  Int3 best{0, 0, 0};
  double best_cost = std::numeric_limits<double>::infinity();
  for (const Int3& p : kPermutations) {
    const Int3 d{factors[p[0]], factors[p[1]], factors[p[2]]};
    if (!keeps(d, forced) || !fits(d)) continue;
    const double c = halo_cost(d, block_of(d));
    if (c < best_cost) best_cost = c, best = d;
  }
  return best;
}

// MPI_Dims_create's balanced grid (keeping `forced`), its factors largest first.
Int3 balanced_factors(int ranks, const Int3& forced) {
  Int3 f = forced;
  MPI_Dims_create(ranks, 3, f.data());
  std::sort(f.begin(), f.end(), std::greater<int>());
  return f;
}

}  // namespace

double halo_cost(const Int3& dims, const Int3& block) {
  const double face[3] = {double(block[1]) * block[2], double(block[0]) * block[2], double(block[0]) * block[1]};
  double cost = 0;
  for (int a = 0; a < 3; ++a) {
    if (dims[a] == 1) continue;
    const double sides = a == 1 ? 2.0 * (dims[1] - 1) / dims[1] : 2.0;
    cost += (a == 0 ? kXFaceWeight : 1.0) * sides * face[a];
  }
  return cost;
}

Int3 choose_block_dims(int ranks, const Int3& block) {
  if (ranks < 1) throw ConfigError("rank count " + std::to_string(ranks) + " must be at least 1");
  return cheapest_permutation(balanced_factors(ranks, {0, 0, 0}), {0, 0, 0}, [](const Int3&) { return true; },
                              [&](const Int3&) { return block; });
}

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
  auto fits = [&](const Int3& d) { return misfit(d, global, min_block).empty(); };
  auto block_of = [&](const Int3& d) { return Int3{global[0] / d[0], global[1] / d[1], global[2] / d[2]}; };
  Int3 best = cheapest_permutation(balanced_factors(ranks, forced), forced, fits, block_of);
  if (best[0] != 0) return best;
  // No balanced grid divides this one: any that does, the cheapest.
  double best_cost = std::numeric_limits<double>::infinity();
  for (int px = 1; px <= ranks; ++px) {
    if (ranks % px || (forced[0] > 0 && px != forced[0])) continue;
    for (int py = 1; py <= ranks / px; ++py) {
      if ((ranks / px) % py || (forced[1] > 0 && py != forced[1])) continue;
      const int pz = ranks / px / py;
      if (forced[2] > 0 && pz != forced[2]) continue;
      const Int3 d{px, py, pz};
      if (!fits(d)) continue;
      const double c = halo_cost(d, block_of(d));
      if (c < best_cost) best_cost = c, best = d;
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

  // The grid is MPI's Cartesian order (row-major, ranks not reordered, so results do not
  // depend on the MPI library's placement) computed here rather than by MPI_Cart_create:
  // a simulated MPI (SimGrid's SMPI) took hours for MPI_Cart_create at 8192 ranks, and the
  // map from coordinates to ranks is a formula.
  MPI_Comm_dup(comm, &cart_);
  MPI_Comm_rank(cart_, &rank_);
  MPI_Comm_size(cart_, &size_);
  coords_ = {rank_ / (dims_[1] * dims_[2]), rank_ / dims_[2] % dims_[1], rank_ % dims_[2]};
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
  for (const int a : {X, Z}) c[a] = (c[a] + dims_[a]) % dims_[a];  // periodic
  return (c[0] * dims_[1] + c[1]) * dims_[2] + c[2];
}

MPI_Comm CartDecomposition::sub_comm(const std::array<bool, 3>& keep) const {
  // MPI_Cart_sub's groups and order: the ranks that share the coordinates of the axes not
  // kept, ordered by rank (row-major order restricted to the kept axes).
  int colour = 0;
  for (int a = 0; a < 3; ++a) colour = colour * dims_[a] + (keep[a] ? 0 : coords_[a]);
  MPI_Comm sub = MPI_COMM_NULL;
  MPI_Comm_split(cart_, colour, rank_, &sub);
  return sub;
}

}  // namespace efsi
