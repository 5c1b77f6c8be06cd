#pragma once
// A STREAM-triad bandwidth probe for the micro-benchmarks' roofline figures:
//   a[i] = b[i] + s c[i]   over three arrays of 2^22 doubles (32 MiB each, 96 MiB in all per
//                          rank: three times the 32 MiB L3 of the dev machine, so it runs
//                          from memory), OpenMP threads as the kernels use them.
// Every rank runs it at the same moment, as every rank runs a kernel at the same moment, so
// the bandwidth it measures is one rank's share of the memory bandwidth when all ranks
// stream together.  Bytes counted the STREAM way: 24 per element (two reads, one write; the
// write-allocate read of a is not counted), the same convention as the kernels' byte counts.
#include <mpi.h>

#include <cstddef>
#include <memory>

#include "kernel_clock.hpp"

namespace efsi::bench {

class TriadProbe {
 public:
  // `sweeps` triads over the arrays per pass (a cache-resident probe needs several to last
  // long enough to time well).
  explicit TriadProbe(std::size_t elements = std::size_t{1} << 22, int sweeps = 1);
  TriadProbe(const TriadProbe&) = delete;
  TriadProbe& operator=(const TriadProbe&) = delete;

  // One triad pass on every rank of `comm`; returns section_times' wall and CPU times
  // (collective).
  Times run(MPI_Comm comm);
  // The least wall and the least CPU time of `passes` passes (collective): the probe's times
  // with the least disturbance.
  Times best(MPI_Comm comm, int passes);
  double bytes() const { return 24.0 * static_cast<double>(n_) * sweeps_; }  // per rank per pass

 private:
  struct Free {
    void operator()(double* p) const noexcept;
  };
  std::size_t n_;
  int sweeps_;
  std::unique_ptr<double[], Free> a_, b_, c_;
};

// The process's probe (made on first use, first-touched by the threads that use it).
TriadProbe& triad_probe();

// The same triad on arrays of 2^14 doubles (3 x 128 KiB: inside each core's 1 MiB L2),
// 64 sweeps a pass: the CI gate's unit of time.  The kernels' data sit largely in cache (a
// 32^3 field is 0.4 MiB with its halo, a 64^3 one 2.3 MiB against 32 MiB of L3), and on the
// dev VM the memory-bound triad's time moves by up to 1.9x from one process to the next (host
// memory traffic, page backing) while the kernels' times do not; the cache-resident triad
// moves with what the kernels' times move with (clock, core, caches).
TriadProbe& cache_triad_probe();

// The probe for the global reduction, whose time a bandwidth probe says nothing about:
// ranks 2r and 2r + 1 bounce one message of `doubles` doubles `round_trips` times (a last
// odd rank idles); returns the least over `passes` passes of section_times' wall and CPU
// time per one-way message (collective).  With one double it is the MPI latency, which moves
// with what sets the reduction's time on a given machine (on the dev VM the latency between
// the two vCPUs changes by 2x from one run to the next: host placement), so the reduction's
// time over it is the machine-independent figure.
Times message_probe(MPI_Comm comm, int passes, std::size_t doubles, int round_trips);

}  // namespace efsi::bench
