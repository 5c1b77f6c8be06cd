#pragma once
// Four-colour SOR for the discrete pressure Poisson equation Lap x = rhs (docs/numerics.md, "SMAC").
//
// Lap is the 7-point operator of laplacian.hpp: periodic in x and z, zero flux
// through the walls in y.  A cell's colour comes from its GLOBAL indices,
// c = (i mod 2) + 2 ((j + k) mod 2), so the six neighbours of a cell never share its
// colour (this needs even global counts in x and z, the periodic directions; y has walls
// and may be odd).  A sweep updates colour 0, 1, 2, 3 in turn with
//   x <- (1 - omega) x + omega (sum_nb w_nb x_nb - rhs) / (sum_nb w_nb),
// w = 1/h^2 per axis; at a wall the neighbour across it is dropped (weight 0 and a smaller
// diagonal), which is the exact Gauss-Seidel update for the zero-flux operator.  Each
// colour reads only other colours, so the field after n sweeps is bitwise the same on
// every decomposition, every thread count, and in both communication modes.  With x whole
// on the rank, colours 0-1 and 2-3 each go in one pass over their rows (a row's ends are
// its own x ghosts); otherwise each colour is a pass.  After every pass:
//   sync:  a blocking halo exchange (Reach::faces) of x;
//   async: begin() the exchange of the pass just done, update the next pass's
//          interior points while it flies (in k-slabs with MPI_Testall between them),
//          finish(), then update that pass's points next to a face whose neighbour is
//          another rank. Faces at a wall (zero weight) or on the rank's own periodic wrap
//          (ghosts copied in begin()) need no wait. The timers show the overlap: halo_wait
//          (the final wait) against the sync mode's blocking halo_mpi.
// The whole field travels each time, less its x faces between fused passes (sending only
// the updated colour would halve it).
//
// Temporal blocking (sweeps_per_exchange K > 1, not the paper's pattern): the K sweeps'
// passes run between two exchanges of a private copy of x (and of rhs, sent once with the
// first) whose ghosts are 2K deep, with edges and corners.  Each pass updates the owned
// points and, beyond each face but a wall (and a fused row's own x ends), the ghosts whose
// neighbours still hold the owner's values (a sweep costs two layers: group_boxes), so the
// owned points get bitwise the values of the exchange after every pass, and the ghosts that
// went stale are never read.  The passes of a group go as a wavefront
// over z planes, so a plane is read from memory about once a group, not once a pass.
// Exchanges per call: ceil(n / K) + 1 instead of n x passes + 1.  Async overlaps each
// exchange with the first pass's interior.
#include <memory>
#include <vector>

#include "comm_mode.hpp"
#include "decomposition.hpp"
#include "domain.hpp"
#include "field.hpp"
#include "paper_constants.hpp"
#include "halo_exchange.hpp"
#include "region_timers.hpp"
#include "work_count.hpp"

namespace efsi {

// The colour updates' timer region.
inline const Region kSorSweepsRegion = define_region("sor_sweeps", false);

// Even global counts in the periodic directions x and z; throws ConfigError otherwise.
void check_sor_grid(const Int3& cells);

class SorPoisson {
 public:
  // x: cell-centred, halo >= 1, WallParity::even, on `decomp`.  Throws ConfigError (on
  // every rank alike, before any communication) for odd global x or z counts, a domain
  // that does not match the decomposition, or an unsuitable field.
  // sweeps_per_exchange: K >= 1 (1: the paper's exchange after every pass); its ghost depth
  // 2K must not exceed the smallest local extent along an axis the passes grow along
  // (ConfigError).  halo: how the blocked exchanges reach edges and corners.
  SorPoisson(const CartDecomposition& decomp, const Domain& domain, Field& x, CommMode comm,
             RegionTimers* timers = nullptr, double omega = paper::kSorOmega, int sweeps_per_exchange = 1,
             HaloPattern halo = HaloPattern::direct);
  SorPoisson(const SorPoisson&) = delete;
  SorPoisson& operator=(const SorPoisson&) = delete;

  // n full sweeps of Lap x = factor rhs on the owned cells (collective).  x's ghosts are
  // brought up to date first and are current again on return.  rhs: only owned cells are
  // read.  factor = 1 is exact (the update multiplies by it), so it costs no accuracy.
  void sweeps(const Field& rhs, int n, double factor = 1.0);

  // Collective: RMS over all owned cells of factor rhs - Lap x, after a ghost update of x.
  double residual_rms(const Field& rhs, double factor = 1.0);

  static int colour(int gi, int gj, int gk) { return (gi & 1) + 2 * ((gj + gk) & 1); }

  double omega() const { return omega_; }
  int sweeps_per_exchange() const { return k_; }
  CommMode comm_mode() const { return comm_; }
  const HaloExchange& halo() const { return halo_; }

 private:
  // The colours updated between two exchanges: `colour` alone, or with colour + 1 in the
  // same pass over each row (pair).
  struct Stage {
    int colour;
    bool pair;
  };
  PerCell pass_cost() const;
  // One pass's points in `box`: a stage of its own (update) or the loops alone, for a caller
  // that charges several boxes as one stage.
  void update(const Field& rhs, double factor, const Stage& stage, const Box& box);
  void update_loops(const Field& rhs, double factor, const Stage& stage, const Box& box);
  template <bool kPair>
  void update_rows(const Field& rhs, double factor, int colour, const Box& box);
  template <bool kPair>
  void rows_in_team(const Field& rhs, double factor, int colour, const Box& box);
  void update_columns(const Field& rhs, double factor, int colour, const Box& box);
  void update_interior(const Field& rhs, double factor, const Stage& stage, HaloExchange& flight, const Box& inner);
  void update_boundary(const Field& rhs, double factor, const Stage& stage, const Box& outer, const Box& inner);
  void blocked_sweeps(const Field& rhs, int n, double factor);
  // The box of each pass of a group of `sweeps` sweeps: the owned points and the ghosts whose
  // update is still the owner's (growing only where grows_lo_ / grows_hi_ say).
  std::vector<Box> group_boxes(int sweeps) const;
  // Passes first .. of a group on the blocked fields, pass m over boxes[m].
  void blocked_passes(const Field& rhs, double factor, int first, const std::vector<Box>& boxes);
  void wavefront(const Field& rhs, double factor, int first, const std::vector<Box>& boxes);

  const CartDecomposition& decomp_;
  Field& x_;
  CommMode comm_;
  RegionTimers* timers_;
  double omega_;
  double inv_h2_[3];
  // Per local j from -depth_: weights of the y neighbours below/above (0 across a wall) and
  // omega / diag.
  std::vector<double> wy_lo_, wy_hi_, omega_over_diag_;
  int k_ = 1;
  int depth_ = 0;  // the blocked fields' ghost depth: 2 k_ (0: not blocked)
  bool grows_lo_[3]{}, grows_hi_[3]{};
  std::unique_ptr<Field> xw_, rw_;
  std::unique_ptr<HaloExchange> wide_first_, wide_x_;  // x and rhs, then x alone
  Field* xs_;  // the field the passes update: x_, or xw_ when blocked
  Box owned_, inner_, blocked_inner_;
  std::vector<Stage> stages_;
  HaloExchange halo_;
  // Between fused stages: y and z only.  A fused row is the whole periodic x extent and sets
  // its own x ghosts before each colour, and no other row reads them, so the x-face copies
  // (one strided value per row) would only repeat that; the last stage's exchange is whole.
  std::unique_ptr<HaloExchange> stage_halo_;
  HaloExchange& between_stages() { return stage_halo_ ? *stage_halo_ : halo_; }
};

}  // namespace efsi
