#include "region_timers.hpp"

namespace efsi {

std::string_view to_string(Region r) {
  switch (r) {
    case Region::compute: return "compute";
    case Region::halo_pack: return "halo_pack";
    case Region::halo_unpack: return "halo_unpack";
    case Region::halo_mpi: return "halo_mpi";
    case Region::halo_wait: return "halo_wait";
    case Region::reduce: return "reduce";
    case Region::sor_sweeps: return "sor_sweeps";
    case Region::fft_solve: return "fft_solve";
    case Region::transpose_mpi: return "transpose_mpi";
    case Region::count: break;
  }
  return "?";
}

TimerReport summarize(const RegionTimers& timers, double elapsed, MPI_Comm comm) {
  // Regions, then elapsed, then comm: one reduction per operator.
  constexpr int n = kRegionCount + 2;
  std::array<double, n> local{};
  for (int r = 0; r < kRegionCount; ++r) local[r] = timers.get(static_cast<Region>(r));
  local[kRegionCount] = elapsed;
  local[kRegionCount + 1] = timers.get(Region::halo_mpi) + timers.get(Region::halo_wait) +
                            timers.get(Region::reduce) + timers.get(Region::transpose_mpi);

  std::array<double, n> lo{}, sum{}, hi{};
  MPI_Allreduce(local.data(), lo.data(), n, MPI_DOUBLE, MPI_MIN, comm);
  MPI_Allreduce(local.data(), sum.data(), n, MPI_DOUBLE, MPI_SUM, comm);
  MPI_Allreduce(local.data(), hi.data(), n, MPI_DOUBLE, MPI_MAX, comm);
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);

  auto spread = [&](int m) { return Spread{lo[m], sum[m] / ranks, hi[m]}; };
  TimerReport rep;
  for (int r = 0; r < kRegionCount; ++r) rep.region[r] = spread(r);
  rep.elapsed = spread(kRegionCount);
  rep.comm = spread(kRegionCount + 1);
  rep.comm_fraction = rep.elapsed.max > 0 ? rep.comm.mean / rep.elapsed.max : 0.0;
  return rep;
}

}  // namespace efsi
