#pragma once
// The 7-point Poisson problem Lap x = factor rhs (docs/numerics.md, "Multigrid solver") solved
// by hypre's Struct interface: PFMG multigrid (red-black Gauss-Seidel, V(2,1), skip-relax,
// non-Galerkin coarse operators), the same discrete operator as the FFT and SOR solvers:
// periodic in x and z (HYPRE_StructGridSetPeriodic), zero flux at the y walls (the
// coefficient across a wall dropped, the diagonal shrunk).  The constant mode is singular:
// the right-hand side is made zero-mean and so is x.
#include <mpi.h>

#include <cstdint>
#include <vector>

#include "decomposition.hpp"
#include "domain.hpp"
#include "field.hpp"
#include "region_timers.hpp"

namespace efsi {

// The solve's own work, and the time inside MPI during it (hypre's exchanges and
// reductions, by PMPI interposition: mpi_interpose.hpp), which counts as communication.
inline const Region kMgSolveRegion = define_region("mg_solve", false);
inline const Region kMgMpiRegion = define_region("mg_mpi", true);

// hypre's PFMG on a periodic axis: N = 2^k or 3 * 2^k (k >= 1); other sizes stall or fail
// to coarsen.  Throws ConfigError naming the axis, the size and the rule.
void check_mg_grid(const Int3& cells);

// How a solve stops: below `tolerance` relative residual ||b - A x|| / ||b|| (x from 0),
// or after `max_cycles` V-cycles, whichever comes first.
struct MgStop {
  double tolerance = 1e-3;
  int max_cycles = 100;
};

// The hypre solver: PFMG alone (the method's), SMG alone, or conjugate gradients
// preconditioned by one PFMG V-cycle.  The others serve the benchmarks' comparison.
enum class MgSolver { pfmg, smg, pcg_pfmg };
const char* to_string(MgSolver s);

struct MgResult {
  int cycles = 0;
  double residual = 0;  // relative, as hypre computes it (0 when it did not)
};

class MgPoisson {
 public:
  // Builds hypre's grid, matrix and solver (set-up, collective); its time goes to setup_seconds.
  MgPoisson(const CartDecomposition& decomp, const Domain& domain, RegionTimers* timers = nullptr,
            MgSolver kind = MgSolver::pfmg);
  ~MgPoisson();
  MgPoisson(const MgPoisson&) = delete;
  MgPoisson& operator=(const MgPoisson&) = delete;

  // x = the zero-mean solution of Lap x = factor (rhs - <rhs>) on the owned cells (ghosts
  // untouched).  Collective.
  MgResult solve(const Field& rhs, Field& x, double factor, const MgStop& stop);
  double setup_seconds() const { return setup_seconds_; }

 private:

  const CartDecomposition& decomp_;
  RegionTimers* timers_;
  MgSolver kind_;
  Int3 lo_{}, hi_{};  // this rank's box, inclusive, global indices
  std::int64_t count_ = 0;
  std::vector<double> values_;
  void* grid_ = nullptr;     // HYPRE_StructGrid
  void* stencil_ = nullptr;  // HYPRE_StructStencil
  void* matrix_ = nullptr;   // HYPRE_StructMatrix
  void* b_ = nullptr;        // HYPRE_StructVector
  void* x_ = nullptr;
  void* solver_ = nullptr;   // HYPRE_StructSolver (kind_)
  void* precond_ = nullptr;  // PFMG under PCG
  double setup_seconds_ = 0;
};

}  // namespace efsi
