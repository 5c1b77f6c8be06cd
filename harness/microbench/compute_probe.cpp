#include "compute_probe.hpp"

#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>

#include "mul_add.hpp"

namespace efsi::bench {
namespace {
constexpr std::size_t kBlock = 2048;  // doubles per thread
constexpr int kChain = 8;             // multiply-add pairs per element
}  // namespace

ComputeProbe::ComputeProbe(int sweeps) : sweeps_(sweeps), threads_(omp_get_max_threads()) {
  data_.assign(kBlock * static_cast<std::size_t>(threads_), 1.0);
}

double ComputeProbe::flops() const { return 2.0 * kChain * kBlock * static_cast<double>(threads_) * sweeps_; }

Times ComputeProbe::run(MPI_Comm comm) {
  // m and c keep x at its fixed point c / (1 - m) = 1: no overflow, no denormals.
  const double m = 0.999999, c = 1e-6;
  double* all = data_.data();
  const int threads = threads_;
  const int sweeps = sweeps_;
  return section_times(comm, [&] {
#pragma omp parallel num_threads(threads)
    {
      double* d = all + kBlock * static_cast<std::size_t>(omp_get_thread_num());
      for (int s = 0; s < sweeps; ++s) {
#pragma omp simd
        for (std::size_t i = 0; i < kBlock; ++i) {
          double x = d[i];
#pragma GCC unroll 8
          for (int r = 0; r < kChain; ++r) x = mul_add(x, m, c);
          d[i] = x;
        }
        benchmark::ClobberMemory();
      }
    }
  });
}

Times ComputeProbe::best(MPI_Comm comm, int passes) { return best_of(passes, [&] { return run(comm); }); }

ComputeProbe& compute_probe() {
  static ComputeProbe probe;
  return probe;
}

}  // namespace efsi::bench
