#include "kernel_timing.hpp"

#include <algorithm>

#include "stream_probe.hpp"

namespace efsi::bench {

void report_kernel(benchmark::State& state, std::vector<Times>& times, const KernelCost& cost) {
  // Every rank holds the same times (section_times) and runs the probe together.
  const Times probe = triad_probe().best(MPI_COMM_WORLD, kProbePasses);
  const Times cache_probe = cache_triad_probe().best(MPI_COMM_WORLD, kProbePasses);
  if (times.empty()) return;
  std::vector<double> wall;
  double cpu_min = times.front().cpu, work_min = times.front().work;
  for (const Times& t : times) {
    wall.push_back(t.wall);
    cpu_min = std::min(cpu_min, t.cpu);
    work_min = std::min(work_min, t.work);
  }
  const double gate = cost.communication ? cpu_min : work_min;
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
  state.counters["work_min_us"] = work_min * 1e6;
  state.counters["gate_us"] = gate * 1e6;
  state.counters["wait_clock"] = mpi_wait_clock_requested() ? 1.0 : 0.0;
  state.counters["bytes_per_cell"] = cost.bytes_per_cell;
  state.counters["flops_per_cell"] = cost.flops_per_cell;
  state.counters["cells"] = cost.cells;
  state.counters["GBps"] = gbps;
  state.counters["GFLOPs"] = t_med > 0 ? flops / t_med / 1e9 : 0.0;
  state.counters["triad_us"] = probe.wall * 1e6;
  state.counters["triad_cpu_us"] = probe.cpu * 1e6;
  state.counters["triad_GBps"] = triad_gbps;
  state.counters["roofline_fraction"] = triad_gbps > 0 ? gbps / triad_gbps : 0.0;
  state.counters["cache_triad_us"] = cache_probe.wall * 1e6;
  state.counters["cache_triad_cpu_us"] = cache_probe.cpu * 1e6;
  state.counters["cache_triad_GBps"] = cache_probe.wall > 0 ? cache_triad_probe().bytes() / cache_probe.wall / 1e9 : 0.0;
  state.counters["ratio"] = cache_probe.cpu > 0 ? gate / cache_probe.cpu : 0.0;
}

}  // namespace efsi::bench
