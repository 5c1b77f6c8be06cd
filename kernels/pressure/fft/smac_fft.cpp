#include "smac_fft.hpp"

#include <mpi.h>

namespace efsi {

void SmacFftPressure::attach(const CartDecomposition& decomp, const Domain& domain, FsiWork& work,
                             RegionTimers& timers) {
  const double t0 = MPI_Wtime();
  fft_ = std::make_unique<FftPoisson>(decomp, domain, planning_, &timers);
  report_.setup_seconds = MPI_Wtime() - t0;
  // grad dp on the owned faces reads the low face ghosts.
  dp_halo_ = std::make_unique<HaloExchange>(decomp, std::vector<Field*>{&work.dp}, Reach::faces, &timers);
}

void SmacFftPressure::increment(PressureInputs& in) {
  // D* sums to the net flux through the boundary, zero to round-off; the solve removes
  // that round-off mean and returns <dp> = 0, so <p> stays where it started.
  fft_->solve(in.work.div, in.work.dp, 1.0 / in.dt);
  dp_halo_->exchange();
}

}  // namespace efsi
