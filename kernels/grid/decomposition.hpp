#pragma once
// Cartesian decomposition of the global cell grid: periodic in x and z, walls in y.
#include <mpi.h>

#include "grid_types.hpp"

namespace efsi {

// An x face weighs this many y or z face cells in halo_cost.  Lines run along x, so an x
// face is packed a value or three per row and the async shell beside it runs strided
// lines; on 2 ranks of a 128 x 64 x 64 channel a cut in x cost more than a cut of twice
// the face cells in y or z (docs/architecture.md, 'Rank grid per method').
inline constexpr double kXFaceWeight = 3.0;

// Face cells a rank of grid `dims` with local `block` exchanges, a mean over the ranks:
// both faces of a cut periodic axis, on y one fewer face than ranks (the walls), x faces
// weighted kXFaceWeight.
double halo_cost(const Int3& dims, const Int3& block);

// Chooses PX x PY x PZ for `ranks` ranks.  Entries of `forced` that are > 0 are kept.
// Takes the permutation of MPI_Dims_create's balanced factors with the least halo_cost
// that divides the grid (ties: y cut before z, z before x); when none divides it, the
// dividing factorisation with the least halo_cost.  Throws ConfigError naming the numbers
// when no decomposition fits (product mismatch, grid not divisible, local block thinner
// than `min_block`).  Pure and deterministic: every rank reaches the same verdict.
Int3 choose_dims(int ranks, const Int3& global_cells, int min_block, const Int3& forced = {0, 0, 0});

// The same choice for a fixed `block` per rank, where the grid times the block is the box
// (weak scaling): the permutation of the balanced factors with the least halo_cost.
Int3 choose_block_dims(int ranks, const Int3& block);

class CartDecomposition {
 public:
  // Collective over `comm`.  Validation happens before any communication, so a bad
  // set-up throws ConfigError on every rank and nobody hangs.
  CartDecomposition(MPI_Comm comm, const Int3& global_cells, int min_block,
                    const Int3& forced = {0, 0, 0});
  ~CartDecomposition();
  CartDecomposition(const CartDecomposition&) = delete;
  CartDecomposition& operator=(const CartDecomposition&) = delete;

  MPI_Comm comm() const { return cart_; }
  int rank() const { return rank_; }
  int size() const { return size_; }
  const Int3& dims() const { return dims_; }
  const Int3& coords() const { return coords_; }
  const Int3& global() const { return global_; }
  const Int3& local() const { return local_; }
  // Global index of the first owned cell along each axis.
  const Int3& offset() const { return offset_; }

  // Local y index of the wall faces y = 0 and y = Ly (outside [0, ny] on ranks away from them).
  int wall_row_below() const { return -offset_[Y]; }
  int wall_row_above() const { return global_[Y] - offset_[Y]; }

  bool wall_below() const { return coords_[Y] == 0; }
  bool wall_above() const { return coords_[Y] == dims_[Y] - 1; }

  // Rank at coords + step (each component in {-1, 0, 1}); MPI_PROC_NULL across a wall.
  int neighbour(const Int3& step) const;

  // Collective: the communicator of the ranks that differ only along the axes `keep` marks,
  // as MPI_Cart_sub would give it (same groups, same order).  The caller frees it.
  MPI_Comm sub_comm(const std::array<bool, 3>& keep) const;

 private:
  MPI_Comm cart_ = MPI_COMM_NULL;
  int rank_ = 0;
  int size_ = 1;
  Int3 dims_{}, coords_{}, global_{}, local_{}, offset_{};
};

}  // namespace efsi
