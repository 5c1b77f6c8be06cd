#pragma once
// Exact solver of the discrete pressure Poisson equation (docs/numerics.md, "Exact FFT solver").
//
// Lap x = rhs on the cell centres, with Lap the 7-point operator of acm.hpp's `laplacian`:
// periodic in x and z, zero flux through the walls in y (even-mirrored ghosts).
// Real FFT (FFTW r2c/c2r) along x, complex FFT along z on the r2c output, where Lap has
// the eigenvalues -(4/h^2) sin^2(pi k/N); then, for every (kx, kz), the tridiagonal system
// in y with zero-flux wall rows, by the Thomas algorithm.  The (0,0) mode is singular:
// its right-hand side is made compatible (the mean of rhs is removed) and its solution is
// shifted to zero mean, so the returned x has zero volume mean.
//
// Parallel on any Cartesian decomposition Px x Py x Pz, with three pencil transposes
// (MPI_Alltoallv, uneven blocks allowed) on Cartesian sub-communicators:
//   block (X_cx, Y_cy, Z_cz)
//     -- x-row comm (Px) -->   x-pencil (all x, Y_cy split Px ways, Z_cz)        x r2c
//     -- z-row comm (Pz) -->   z-pencil (kx split Pz ways, same y, all z)        z c2c
//     -- xy-plane comm (PxPy) --> y-pencil (same kx, all y, kz split PxPy ways)  Thomas
// and back the same way.  Nothing is gathered onto one rank.
#include <mpi.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "decomposition.hpp"
#include "domain.hpp"
#include "field.hpp"
#include "region_timers.hpp"

namespace efsi {

// The solve's timer regions: FFTs, Thomas and reordering; the transposes' MPI_Alltoallv.
inline const Region kFftSolveRegion = define_region("fft_solve", false);
inline const Region kTransposeRegion = define_region("transpose_mpi", true);

class FftPoisson {
 public:
  // estimate: FFTW_ESTIMATE (instant set-up); measure: FFTW_MEASURE (set-up times the
  // candidate plans once, faster solves).  Plans are made here once and reused.
  enum class Planning { estimate, measure };

  // Collective over decomp.comm().  domain.cells must equal decomp.global().
  // FFTW runs with omp_get_max_threads() threads.
  // timers (optional): the solve's MPI_Alltoallv time goes to kTransposeRegion (counted as
  // communication), the rest of it to kFftSolveRegion.
  FftPoisson(const CartDecomposition& decomp, const Domain& domain, Planning planning = Planning::measure,
             RegionTimers* timers = nullptr);
  ~FftPoisson();
  FftPoisson(const FftPoisson&) = delete;
  FftPoisson& operator=(const FftPoisson&) = delete;

  // Reads rhs on the owned cells, writes x on the owned cells (ghosts untouched).
  // rhs and x: cell-centred fields of the constructor's decomposition.  Collective.
  // Solves Lap x = factor (rhs - <rhs>) with <x> = 0 (the factor costs nothing: it is
  // folded into the spectral division).
  void solve(const Field& rhs, Field& x, double factor = 1.0);

  // Doubles this rank sends through MPI_Alltoallv in one solve (all six transposes).
  std::int64_t doubles_sent() const;

  // One pencil transpose between two box layouts inside a sub-communicator.
  struct Transpose {
    MPI_Comm comm = MPI_COMM_NULL;
    int elem = 1;  // doubles per element (1 real, 2 complex)
    std::int64_t volume = 0;  // elements of the source box
    std::vector<std::int64_t> send_idx, recv_idx;  // element positions in src / dst buffers
    std::vector<int> send_counts, send_displs, recv_counts, recv_displs;  // in doubles
    std::vector<double> send_buf, recv_buf;
    double mpi_seconds = 0.0;  // MPI_Alltoallv time of the current solve
    bool identity = false;     // one rank, the same box and order on both sides: a copy
    void forward(const double* src, double* dst);   // src layout -> dst layout
    void backward(const double* dst, double* src);  // dst layout -> src layout
  };

 private:
  struct FftwBuf {
    void operator()(void* p) const noexcept;
  };
  using Buf = std::unique_ptr<double[], FftwBuf>;

  RegionTimers* timers_ = nullptr;
  Int3 n_global_{}, n_local_{};
  double inv_h2_[3]{};
  int mx_ = 0;                 // Nx/2 + 1
  std::int64_t lines_x_ = 0;   // x-lines on this rank in the x-pencil
  std::int64_t lines_z_ = 0;   // z-lines in the z-pencil
  // The y-pencil as [outer][y][lane]: lanes (the axes stored before y) run contiguous, so
  // the tridiagonal solves vectorise across them.
  std::int64_t lanes_ = 0, outer_ = 0;
  std::vector<double> lam_lane_;  // lambda_x + lambda_z per lane, [outer][lane]
  std::int64_t singular_ = -1;    // position of the (0, 0) mode's first point, or -1
  MPI_Comm comm_x_ = MPI_COMM_NULL, comm_z_ = MPI_COMM_NULL, comm_xy_ = MPI_COMM_NULL;
  Transpose t1_, t2_, t3_;
  Buf b0_, b1_, b1c_, b2_, b3_;
  double *p0_ = nullptr, *p1_ = nullptr, *p1c_ = nullptr, *p2_ = nullptr, *p3_ = nullptr;  // b*_ or shared
  void* plan_r2c_ = nullptr;
  void* plan_c2r_ = nullptr;
  void* plan_zf_ = nullptr;
  void* plan_zb_ = nullptr;
  std::vector<double> lam_x_, lam_z_;  // eigenvalues of the x and z parts of Lap
};

}  // namespace efsi
