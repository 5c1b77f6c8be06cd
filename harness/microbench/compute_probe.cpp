#include "compute_probe.hpp"

#include <benchmark/benchmark.h>
#include <omp.h>

#include <cmath>

#include "kernel_costs.hpp"
#include "mul_add.hpp"
#include "weno5.hpp"

namespace efsi::bench {
namespace {
constexpr int kChain = 8;  // multiply-add pairs per element
constexpr int kReach = 3;  // the WENO5 stencil's half-width
}  // namespace

ComputeProbe::ComputeProbe(Mix mix)
    : mix_(mix),
      sweeps_(mix == Mix::multiply_add ? 4096 : 1024),
      points_(mix == Mix::multiply_add ? 2048 : 1024),
      data_(static_cast<std::size_t>(omp_get_max_threads())) {
  const std::size_t n = points_;
#pragma omp parallel num_threads(static_cast<int>(data_.size()))
  {
    std::vector<double>& d = data_[static_cast<std::size_t>(omp_get_thread_num())];
    if (mix_ == Mix::multiply_add) {
      d.assign(n, 1.0);
    } else {  // q with its reach on both sides, then vel, then out
      d.assign(n + 2 * kReach + 2 * n, 0.0);
      for (std::size_t i = 0; i < n + 2 * kReach; ++i) d[i] = std::sin(0.3 * double(i)) + 0.1 * std::cos(1.7 * double(i));
      for (std::size_t i = 0; i < n; ++i) d[n + 2 * kReach + i] = std::sin(0.05 * double(i) + 0.5);
    }
  }
}

double ComputeProbe::flops() const {
  const double per_point = mix_ == Mix::multiply_add ? 2.0 * kChain : kWenoAdvectionFlops;
  return per_point * static_cast<double>(points_) * static_cast<double>(data_.size()) * sweeps_;
}

void ComputeProbe::multiply_add_sweeps(double* d) const {
  // m and c keep x at its fixed point c / (1 - m) = 1: no overflow, no denormals.
  const double m = 0.999999, c = 1e-6;
  const std::size_t n = points_;
  for (int s = 0; s < sweeps_; ++s) {
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i) {
      double x = d[i];
#pragma GCC unroll 8
      for (int r = 0; r < kChain; ++r) x = mul_add(x, m, c);
      d[i] = x;
    }
    benchmark::ClobberMemory();
  }
}

void ComputeProbe::weno5_sweeps(double* d) const {
  const Weno5Axis axis(16.0);
  const std::size_t n = points_;
  const double* q = d + kReach;
  const double* vel = d + n + 2 * kReach;
  double* out = d + 2 * n + 2 * kReach;
  for (int s = 0; s < sweeps_; ++s) {
#pragma omp simd
    for (std::size_t i = 0; i < n; ++i)
      out[i] = weno5_advection(q[i - 3], q[i - 2], q[i - 1], q[i], q[i + 1], q[i + 2], q[i + 3], vel[i], axis);
    benchmark::ClobberMemory();
  }
}

Times ComputeProbe::run(MPI_Comm comm) {
  return section_times(comm, [&] {
#pragma omp parallel num_threads(static_cast<int>(data_.size()))
    {
      double* d = data_[static_cast<std::size_t>(omp_get_thread_num())].data();
      if (mix_ == Mix::multiply_add) multiply_add_sweeps(d);
      else weno5_sweeps(d);
    }
  });
}

Times ComputeProbe::best(MPI_Comm comm, int passes) { return best_of(passes, [&] { return run(comm); }); }

ComputeProbe& compute_probe(ComputeProbe::Mix mix) {
  static ComputeProbe multiply_add(ComputeProbe::Mix::multiply_add), weno5(ComputeProbe::Mix::weno5);
  return mix == ComputeProbe::Mix::multiply_add ? multiply_add : weno5;
}

}  // namespace efsi::bench
