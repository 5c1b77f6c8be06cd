#pragma once
// A compute-roof probe beside the triad probe (stream_probe.hpp): the multiply-add of the
// stencils, vectorised as they are.  It is the fused mul_add (mul_add.hpp) the WENO5 and
// stretching loops use where the target has FMA, so the roof is the core's peak: on a core
// whose FMA units also do every multiply and add (Intel), twice what separate multiplies and
// adds reach; on Zen 4, whose separate adders stay idle here, the same.
//   x = mul_add(x, m, c), 8 times per element in a row, over 2048 doubles (16 KiB: L1-resident), so
//   the loop is bound by the floating-point pipes, not by memory; lanes and iterations are
//   independent chains, enough of them in flight to hide the latency.
// Every rank runs it at the same moment with its OpenMP threads, as the kernels run, so the
// rate it measures is one rank's share of the cores when all ranks compute together.
#include <mpi.h>

#include <cstddef>
#include <vector>

#include "kernel_clock.hpp"

namespace efsi::bench {

class ComputeProbe {
 public:
  explicit ComputeProbe(int sweeps = 4096);
  // One pass on every rank of `comm` (collective).
  Times run(MPI_Comm comm);
  // The least wall and CPU times of `passes` passes (collective).
  Times best(MPI_Comm comm, int passes);
  double flops() const;  // per rank per pass

 private:
  int sweeps_;
  std::vector<double> data_;  // one block per thread
  int threads_;
};

// The process's probe (made on first use).
ComputeProbe& compute_probe();

}  // namespace efsi::bench
