#pragma once
// Compute-roof probes beside the triad probe (stream_probe.hpp), one per arithmetic mix the
// kernels are measured against (kernel_timing.hpp's roof_fraction).  Every rank runs one at
// the same moment with its OpenMP threads, as the kernels run, so the rate it measures is
// one rank's share of the cores when all ranks compute together.  Data are L1-resident, so
// the loops are bound by the floating-point pipes, not by memory; lanes and iterations are
// independent, enough of them in flight to hide the latency.
//
// Mix::multiply_add, the core's peak: the fused mul_add (mul_add.hpp) the WENO5 and
// stretching loops use where the target has FMA.  On a core whose FMA units also do every
// multiply and add (Intel), twice what separate multiplies and adds reach; on Zen 4, whose
// separate adders stay idle here, the same.
//   x = mul_add(x, m, c), 8 times per element in a row, over 2048 doubles (16 KiB).
//
// Mix::weno5, the transport's own roof: weno5.hpp's weno5_advection, the very function the
// transport inlines 21 times per cell, vectorised as the transport's lines are.  Its
// arithmetic is not a stream of FMAs: about a third of its vector instructions are; the rest
// are single adds, multiplies, selects and one division, each taking a pipe for one flop or
// none.  No code evaluating this scheme reaches the FMA peak, so the transport's distance
// from its roof is measured against what the core does with this mix when memory is out of
// the way.
//   out[i] = weno5_advection(q[i-3..i+3], vel[i]) over 1024 points (24 KiB), smooth and
//   rough data, velocities of both signs.
#include <mpi.h>

#include <cstddef>
#include <vector>

#include "kernel_clock.hpp"

namespace efsi::bench {

class ComputeProbe {
 public:
  enum class Mix { multiply_add, weno5 };
  explicit ComputeProbe(Mix mix);
  // One pass on every rank of `comm` (collective).
  Times run(MPI_Comm comm);
  // The least wall and CPU times of `passes` passes (collective).
  Times best(MPI_Comm comm, int passes);
  double flops() const;  // per rank per pass

 private:
  Mix mix_;
  int sweeps_;
  std::size_t points_;                    // per thread
  std::vector<std::vector<double>> data_;  // one block per thread, filled by its thread
  void multiply_add_sweeps(double* d) const;
  void weno5_sweeps(double* d) const;
};

// The process's probe of each mix (made on first use).
ComputeProbe& compute_probe(ComputeProbe::Mix mix = ComputeProbe::Mix::multiply_add);

}  // namespace efsi::bench
