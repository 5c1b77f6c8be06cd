#include "calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "config_error.hpp"
#include "memory_estimate.hpp"
#include "method_spec.hpp"

namespace efsi {
namespace {

// The case advanced to the developed state: c with the exact FFT SMAC.
ChannelCase reference_case(const ChannelCase& c) {
  ChannelCase ref = c;
  ref.method = configure_method("fft", {}, c.solver.cn_sweeps);
  return ref;
}

double rms_owned(const Field& f, const CartDecomposition& decomp) {
  const Int3 n = f.n();
  double sum = 0.0, total = 0.0;
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) sum += f(i, j, k) * f(i, j, k);
  MPI_Allreduce(&sum, &total, 1, MPI_DOUBLE, MPI_SUM, decomp.comm());
  return std::sqrt(total / double(product(decomp.global())));
}

}  // namespace

Calibration calibrate(const ChannelCase& c, const CartDecomposition& decomp, const std::vector<Particle>& particles,
                      long warmup, const std::vector<double>& eps, int max_iterations) {
  auto counter = c.method.spec->iteration_counter(decomp, c.domain);
  if (!counter) throw ConfigError("method " + c.method.name() + " has no iteration count to calibrate");
  auto solver = build_solver(reference_case(c), decomp, particles);
  solver->impose_laminar_flow();
  for (long s = 0; s <= warmup; ++s) solver->step();
  solver->complete_exchange();

  // The last step's D* (before its exact correction) and its exact dp.
  const Field& div = solver->work().div;
  const Field& dp_fft = solver->work().dp;
  const double factor = 1.0 / c.solver.dt;
  Calibration out;
  out.initial_residual = rms_owned(div, decomp) * factor;
  double tightest = 1.0;
  for (double e : eps) tightest = std::min(tightest, e);
  out.history = counter->residuals(div, factor, tightest, max_iterations);
  for (double e : eps) {
    int n = -1;
    for (std::size_t m = 0; m < out.history.size(); ++m)
      if (out.history[m] <= e) {
        n = static_cast<int>(m) + 1;
        break;
      }
    out.iterations.push_back(n);
  }

  const Field& x = counter->solution();
  double diff = 0.0, ref_max = 0.0;
  const Int3 n = x.n();
  // An iteration may leave the mean of dp free (SOR does); compare after removing it.
  double sums[2] = {0, 0}, global[2] = {0, 0};
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) sums[0] += x(i, j, k), sums[1] += dp_fft(i, j, k);
  MPI_Allreduce(sums, global, 2, MPI_DOUBLE, MPI_SUM, decomp.comm());
  const double cells = double(product(decomp.global()));
  const double shift = (global[0] - global[1]) / cells;
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) {
        diff = std::max(diff, std::fabs(x(i, j, k) - shift - dp_fft(i, j, k)));
        ref_max = std::max(ref_max, std::fabs(dp_fft(i, j, k)));
      }
  double local[2] = {diff, ref_max}, maxes[2] = {0, 0};
  MPI_Allreduce(local, maxes, 2, MPI_DOUBLE, MPI_MAX, decomp.comm());
  out.fft_difference = maxes[1] > 0 ? maxes[0] / maxes[1] : 0.0;
  return out;
}

std::size_t calibration_memory(const ChannelCase& c, const Int3& local, const Int3& dims) {
  return estimate_rank_memory(reference_case(c), local, dims).total() +
         static_cast<std::size_t>(c.method.spec->extra_bytes(local, dims));
}

}  // namespace efsi
