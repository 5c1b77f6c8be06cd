#include "kernel_timing.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "compute_probe.hpp"
#include "stream_probe.hpp"

namespace efsi::bench {
namespace {
std::string g_kernel_name;
}

bool count_mode() {
  static const bool on = [] {
    const char* v = std::getenv("EFSI_COUNT");
    return v && std::strcmp(v, "1") == 0;
  }();
  return on;
}

void start_counting_once() {
  static const bool started = [] {
    callgrind_start_instrumentation();
    return true;
  }();
  (void)started;
}

void set_kernel_name(const std::string& name) { g_kernel_name = name; }
const std::string& kernel_name() { return g_kernel_name; }

void report_kernel(benchmark::State& state, std::vector<Times>& times, const KernelCost& cost) {
  // Every rank holds the same times (section_times) and runs the probe together.
  const Times probe = triad_probe().best(MPI_COMM_WORLD, kProbePasses);
  const Times compute = compute_probe().best(MPI_COMM_WORLD, kProbePasses);
  ComputeProbe& weno_probe = compute_probe(ComputeProbe::Mix::weno5);
  const Times weno = weno_probe.best(MPI_COMM_WORLD, kProbePasses);
  if (times.empty()) return;
  std::vector<double> wall;
  double cpu_min = times.front().cpu;
  for (const Times& t : times) {
    wall.push_back(t.wall);
    cpu_min = std::min(cpu_min, t.cpu);
  }
  std::sort(wall.begin(), wall.end());
  const std::size_t m = wall.size();
  const double t_min = wall.front();
  const double t_med = m % 2 ? wall[m / 2] : 0.5 * (wall[m / 2 - 1] + wall[m / 2]);
  const double bytes = cost.bytes_per_cell * cost.cells, flops = cost.flops_per_cell * cost.cells;
  const double gbps = t_med > 0 ? bytes / t_med / 1e9 : 0.0;
  const double triad_gbps = probe.wall > 0 ? triad_probe().bytes() / probe.wall / 1e9 : 0.0;
  state.counters["min_us"] = t_min * 1e6;
  state.counters["median_us"] = t_med * 1e6;
  state.counters["cpu_min_us"] = cpu_min * 1e6;
  state.counters["bytes_per_cell"] = cost.bytes_per_cell;
  state.counters["flops_per_cell"] = cost.flops_per_cell;
  state.counters["weno_flops_per_cell"] = cost.weno_flops_per_cell;
  state.counters["cells"] = cost.cells;
  state.counters["GBps"] = gbps;
  state.counters["GFLOPs"] = t_med > 0 ? flops / t_med / 1e9 : 0.0;
  state.counters["triad_us"] = probe.wall * 1e6;
  state.counters["triad_GBps"] = triad_gbps;
  state.counters["roofline_fraction"] = triad_gbps > 0 ? gbps / triad_gbps : 0.0;
  // The roofline: the time the counted flops and bytes need at least is the larger of the
  // bandwidth bound and the compute bound, each flop at the roof of its own arithmetic;
  // the kernel's fraction of that roof is roof time over measured time.
  const double peak = compute.wall > 0 ? compute_probe().flops() / compute.wall / 1e9 : 0.0;
  const double weno_peak = weno.wall > 0 ? weno_probe.flops() / weno.wall / 1e9 : 0.0;
  const double gflops = t_med > 0 ? flops / t_med / 1e9 : 0.0;
  const double weno_flops = cost.weno_flops_per_cell * cost.cells;
  const double t_bytes = triad_gbps > 0 ? bytes / triad_gbps / 1e9 : 0.0;
  const double t_compute = (peak > 0 ? (flops - weno_flops) / peak / 1e9 : 0.0) +
                           (weno_peak > 0 ? weno_flops / weno_peak / 1e9 : 0.0);
  state.counters["compute_GFLOPs"] = peak;
  state.counters["compute_fraction"] = peak > 0 ? gflops / peak : 0.0;
  state.counters["weno_GFLOPs"] = weno_peak;
  state.counters["roof_fraction"] = t_med > 0 ? std::max(t_bytes, t_compute) / t_med : 0.0;
}

void report_counts(benchmark::State& state, const MpiCensus& used, const KernelCost& cost, int calls) {
  const double units = static_cast<double>(calls) * cost.units;
  const double local[4] = {static_cast<double>(used.messages), static_cast<double>(used.bytes),
                           static_cast<double>(used.collectives), static_cast<double>(used.collective_bytes)};
  double most[4] = {0, 0, 0, 0};
  MPI_Allreduce(local, most, 4, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  state.counters["units"] = units;
  state.counters["cells"] = cost.cells;
  state.counters["mpi_messages"] = most[0] / units;
  state.counters["mpi_bytes"] = most[1] / units;
  state.counters["mpi_collectives"] = most[2] / units;
  state.counters["mpi_collective_bytes"] = most[3] / units;
  state.counters["bytes_per_cell"] = cost.bytes_per_cell;
  state.counters["flops_per_cell"] = cost.flops_per_cell;
}

}  // namespace efsi::bench
