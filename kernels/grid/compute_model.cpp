#include "compute_model.hpp"

#include <mpi.h>

#include <algorithm>
#include <cstdlib>
#include <limits>

#include "config_error.hpp"

#ifdef EFSI_SIMGRID
#include <simgrid/host.h>
#include <smpi/smpi.h>
#endif

namespace efsi {
namespace {

NodeModel g_model;

}  // namespace

const NodeModel& node_model() { return g_model; }

#ifdef EFSI_SIMGRID

namespace {

double host_property(const char* name, double fallback) {
  const char* v = sg_host_get_property_value(sg_host_self(), name);
  if (!v) return fallback;
  char* end = nullptr;
  const double x = std::strtod(v, &end);
  if (end == v || *end != '\0' || !(x > 0))
    throw ConfigError(std::string("platform host ") + sg_host_self_get_name() + ": property " + name + " = '" + v +
                      "' is not a positive number");
  return x;
}

}  // namespace

void init_compute_model() {
  g_model.host = sg_host_self_get_name();
  const char* platform = sg_host_get_property_value(sg_host_self(), "platform");
  g_model.platform = platform ? platform : g_model.host;
  g_model.core_flops = sg_host_get_speed(sg_host_self());
  g_model.cores_on_node = sg_host_core_count(sg_host_self());
  g_model.node_bandwidth = host_property("memory_bandwidth", 0.0);
  g_model.core_bandwidth = host_property("core_bandwidth", std::numeric_limits<double>::infinity());
  g_model.sockets = static_cast<int>(host_property("sockets", 1.0));
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int local = 0;
  MPI_Comm_size(node, &g_model.ranks_on_node);
  MPI_Comm_rank(node, &local);
  MPI_Comm_free(&node);
  // By-core placement: socket 0's cores first, then socket 1's; ranks beyond the cores
  // wrap round the sockets again.
  const int per_socket = std::max(1, g_model.cores_on_node / g_model.sockets);
  auto socket_of = [&](int r) { return (r / per_socket) % g_model.sockets; };
  g_model.ranks_on_socket = 0;
  for (int r = 0; r < g_model.ranks_on_node; ++r) g_model.ranks_on_socket += socket_of(r) == socket_of(local) ? 1 : 0;
  int missing = g_model.node_bandwidth > 0 ? 0 : 1, any = 0;
  MPI_Allreduce(&missing, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (any)
    throw ConfigError("platform host " + g_model.host +
                      " has no property memory_bandwidth (B/s of the node): the compute model needs it");
  g_model.efficiency = 1.0;
}

void use_efficiency_of(const std::string& method) {
  g_model.efficiency = host_property(("efficiency:" + method).c_str(), 1.0);
  g_model.sweep_efficiency = host_property(("efficiency:" + method + "-sweeps").c_str(), g_model.efficiency);
}

void charge_compute(PerCell cost, double cells, Efficiency e) {
  const double F = g_model.core_flops;
  const double share =
      std::min(g_model.core_bandwidth, g_model.node_bandwidth / g_model.sockets / g_model.ranks_on_socket);
  const double by_bytes = cost.bytes * cells * F / share;
  const double flops =
      std::max(cost.flops * cells, by_bytes) / (e == Efficiency::sweeps ? g_model.sweep_efficiency : g_model.efficiency);
  if (flops > 0) smpi_execute_flops(flops);
}

#else

void init_compute_model() {}
void use_efficiency_of(const std::string&) {}
void charge_compute(PerCell, double, Efficiency) {}

#endif

}  // namespace efsi
