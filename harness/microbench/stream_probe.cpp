#include "stream_probe.hpp"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <new>
#include <vector>


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

Times TriadProbe::best(MPI_Comm comm, int passes) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  Times t{inf, inf, inf};
  for (int p = 0; p < passes; ++p) {
    const Times r = run(comm);
    t.wall = std::min(t.wall, r.wall);
    t.cpu = std::min(t.cpu, r.cpu);
    t.work = std::min(t.work, r.work);
  }
  return t;
}

Times message_probe(MPI_Comm comm, int passes, std::size_t doubles, int round_trips) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int peer = (rank % 2 == 0) ? rank + 1 : rank - 1;
  const bool active = peer < size;
  std::vector<double> message(std::max<std::size_t>(doubles, 1), 1.0);
  const int count = static_cast<int>(message.size());
  constexpr double inf = std::numeric_limits<double>::infinity();
  Times t{inf, inf, inf};
  const double per = 2.0 * round_trips;
  for (int p = 0; p < passes; ++p) {
    const Times r = section_times(comm, [&] {
      if (!active) return;
      for (int n = 0; n < round_trips; ++n) {
        if (rank % 2 == 0) {
          MPI_Send(message.data(), count, MPI_DOUBLE, peer, 0, comm);
          MPI_Recv(message.data(), count, MPI_DOUBLE, peer, 0, comm, MPI_STATUS_IGNORE);
        } else {
          MPI_Recv(message.data(), count, MPI_DOUBLE, peer, 0, comm, MPI_STATUS_IGNORE);
          MPI_Send(message.data(), count, MPI_DOUBLE, peer, 0, comm);
        }
      }
    });
    t.wall = std::min(t.wall, r.wall / per);
    t.cpu = std::min(t.cpu, r.cpu / per);
    t.work = std::min(t.work, r.work / per);
  }
  return t;
}

TriadProbe& triad_probe() {
  static TriadProbe probe;
  return probe;
}

TriadProbe& cache_triad_probe() {
  static TriadProbe probe(std::size_t{1} << 14, 64);
  return probe;
}

}  // namespace efsi::bench
