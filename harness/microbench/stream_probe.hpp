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

}  // namespace efsi::bench
