#include "region_timers.hpp"

#include <stdexcept>
#include <vector>

namespace efsi {

namespace {

struct RegionInfo {
  std::string name;
  bool communication;
};

std::vector<RegionInfo>& table() {
  static std::vector<RegionInfo> t{{"compute", false},  {"halo_pack", false}, {"halo_unpack", false},
                                   {"halo_mpi", true},  {"halo_wait", true},  {"reduce", true}};
  return t;
}

}  // namespace

Region define_region(std::string_view name, bool communication) {
  auto& t = table();
  if (static_cast<int>(t.size()) >= kMaxRegions)
    throw std::logic_error("more than " + std::to_string(kMaxRegions) + " timer regions");
  t.push_back({std::string(name), communication});
  return Region{static_cast<int>(t.size()) - 1};
}

int region_count() { return static_cast<int>(table().size()); }
std::string_view to_string(Region r) { return table().at(r.id).name; }
bool is_communication(Region r) { return table().at(r.id).communication; }

TimerReport summarize(const RegionTimers& timers, double elapsed, MPI_Comm comm) {
  // Regions, then elapsed, then comm: one reduction per operator.
  constexpr int n = kMaxRegions + 2;
  std::array<double, n> local{};
  for (int r = 0; r < region_count(); ++r) {
    local[r] = timers.get(Region{r});
    if (is_communication(Region{r})) local[kMaxRegions + 1] += local[r];
  }
  local[kMaxRegions] = elapsed;

  std::array<double, n> lo{}, sum{}, hi{};
  MPI_Allreduce(local.data(), lo.data(), n, MPI_DOUBLE, MPI_MIN, comm);
  MPI_Allreduce(local.data(), sum.data(), n, MPI_DOUBLE, MPI_SUM, comm);
  MPI_Allreduce(local.data(), hi.data(), n, MPI_DOUBLE, MPI_MAX, comm);
  int ranks = 1;
  MPI_Comm_size(comm, &ranks);

  auto spread = [&](int m) { return Spread{lo[m], sum[m] / ranks, hi[m]}; };
  TimerReport rep;
  for (int r = 0; r < region_count(); ++r) rep.region[r] = spread(r);
  rep.elapsed = spread(kMaxRegions);
  rep.comm = spread(kMaxRegions + 1);
  rep.comm_fraction = rep.elapsed.max > 0 ? rep.comm.mean / rep.elapsed.max : 0.0;
  return rep;
}

}  // namespace efsi
