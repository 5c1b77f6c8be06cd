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
  explicit TriadProbe(std::size_t elements = std::size_t{1} << 22);
  TriadProbe(const TriadProbe&) = delete;
  TriadProbe& operator=(const TriadProbe&) = delete;

  // One triad pass on every rank of `comm`; returns section_times' wall and CPU times
  // (collective).
  Times run(MPI_Comm comm);
  // The least wall and the least CPU time of `passes` passes (collective): the probe's times
  // with the least disturbance.
  Times best(MPI_Comm comm, int passes);
  double bytes() const { return 24.0 * static_cast<double>(n_); }  // per rank per pass

 private:
  struct Free {
    void operator()(double* p) const noexcept;
  };
  std::size_t n_;
  std::unique_ptr<double[], Free> a_, b_, c_;
};

// The process's probe (made on first use, first-touched by the threads that use it).
TriadProbe& triad_probe();

// The probe for the communication kernels (halo exchange, global reduction), whose time a
// memory-bandwidth probe says little about: ranks 2r and 2r + 1 bounce one message of
// `doubles` doubles `round_trips` times (a last odd rank idles); returns the least over
// `passes` passes of section_times' wall and CPU time per one-way message (collective).
// It moves with what sets those kernels' time on a given machine (how far apart the cores
// are, the MPI shared-memory path), so their time over it is the machine-independent figure:
// one double for the reduction (the latency), an exchange's bytes for the halo exchange.
Times message_probe(MPI_Comm comm, int passes, std::size_t doubles, int round_trips);

}  // namespace efsi::bench
