#include "stream_probe.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <new>

namespace efsi::bench {

void TriadProbe::Free::operator()(double* p) const noexcept { std::free(p); }

namespace {
double* alloc_doubles(std::size_t n) {
  void* p = std::aligned_alloc(64, ((n * sizeof(double) + 63) / 64) * 64);
  if (!p) throw std::bad_alloc();
  return static_cast<double*>(p);
}
}  // namespace

TriadProbe::TriadProbe(std::size_t elements, int sweeps)
    : n_(elements),
      sweeps_(sweeps),
      a_(alloc_doubles(elements)),
      b_(alloc_doubles(elements)),
      c_(alloc_doubles(elements)) {
  double *a = a_.get(), *b = b_.get(), *c = c_.get();
  const long n = static_cast<long>(n_);
  // First touch with the same static schedule as the pass, so pages sit near their thread.
#pragma omp parallel for schedule(static)
  for (long i = 0; i < n; ++i) {
    a[i] = 0.0;
    b[i] = 1.0;
    c[i] = 2.0;
  }
}

Times TriadProbe::run(MPI_Comm comm) {
  double* a = a_.get();
  const double *b = b_.get(), *c = c_.get();
  const long n = static_cast<long>(n_);
  const double s = 3.0;
  return section_times(comm, [&] {
    for (int sweep = 0; sweep < sweeps_; ++sweep) {
#pragma omp parallel for simd schedule(static)
      for (long i = 0; i < n; ++i) a[i] = b[i] + s * c[i];
      benchmark::ClobberMemory();
    }
  });
}

Times TriadProbe::best(MPI_Comm comm, int passes) { return best_of(passes, [&] { return run(comm); }); }

TriadProbe& triad_probe() {
  static TriadProbe probe;
  return probe;
}

}  // namespace efsi::bench
