#include "memory_estimate.hpp"

#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "config_error.hpp"
#include "field.hpp"
#include "simulation.hpp"

namespace efsi {
namespace {

// MemAvailable in bytes, or -1 where it cannot be read. EFSI_MEMINFO names a file to read
// instead of /proc/meminfo: test-only, so that the driver tests can fake a small node.
double mem_available_bytes() {
  const char* fake = std::getenv("EFSI_MEMINFO");
  std::ifstream in(fake && *fake ? fake : "/proc/meminfo");
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::string key, unit;
    double value = 0;
    if (fields >> key >> value >> unit && key == "MemAvailable:") return unit == "kB" ? value * 1024.0 : -1.0;
  }
  return -1.0;
}

// "651.2 GiB", "22.9 GiB", "0.00386 GiB": three figures, and no small node shown as 0.
std::string gib_text(double bytes) {
  char b[32];
  std::snprintf(b, sizeof b, gib(bytes) >= 100 ? "%.1f GiB" : "%.3g GiB", gib(bytes));
  return b;
}

}  // namespace

MemoryEstimate estimate_rank_memory(const ChannelCase& c, const Int3& local, const Int3& dims) {
  ChannelCase probe = c;
  probe.domain.cells = {16, 16, 16};
  for (int a = 0; a < 3; ++a) probe.domain.length[a] = 16 * c.domain.spacing(a);
  probe.forced_dims = {1, 1, 1};
  probe.particles = 0;
  probe.slab = 0;
  CartDecomposition dec(MPI_COMM_SELF, probe.domain.cells, 1, probe.forced_dims);
  FieldRecorder recorder;
  { auto solver = build_solver(probe, dec, {}); }

  MemoryEstimate m;
  m.fields = static_cast<int>(recorder.specs().size());
  for (const FieldSpec& f : recorder.specs())
    m.field_bytes += Field::allocation_doubles(local, f.halo) * sizeof(double);
  m.solver_bytes = static_cast<std::size_t>(c.method.spec->extra_bytes(local, dims));
  return m;
}

double gib(double bytes) { return bytes / (1024.0 * 1024.0 * 1024.0); }

void check_node_memory(std::size_t rank_bytes, bool force) {
  int world_rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &world_rank);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, world_rank, MPI_INFO_NULL, &node);
  int node_rank = 0, node_ranks = 1;
  MPI_Comm_rank(node, &node_rank);
  MPI_Comm_size(node, &node_ranks);
  // The ranks of a node can hold blocks of different sizes: the node needs their sum.
  const double mine = double(rank_bytes);
  double need = 0, largest = 0;
  MPI_Allreduce(&mine, &need, 1, MPI_DOUBLE, MPI_SUM, node);
  MPI_Allreduce(&mine, &largest, 1, MPI_DOUBLE, MPI_MAX, node);
  // One reading per node, so that its ranks cannot disagree on a figure that moves.
  double available = node_rank == 0 ? mem_available_bytes() : 0.0;
  MPI_Bcast(&available, 1, MPI_DOUBLE, 0, node);
  MPI_Comm_free(&node);

  // The node shortest of memory decides for the world, and its figures make the line every
  // rank throws: a node that refused alone would leave the others waiting in the run.
  struct {
    double value;
    int rank;
  } shortfall{available >= 0 ? need - available : -INFINITY, world_rank}, worst{};
  MPI_Allreduce(&shortfall, &worst, 1, MPI_DOUBLE_INT, MPI_MAXLOC, MPI_COMM_WORLD);
  const int counts[2] = {node_rank == 0 ? 1 : 0, node_rank == 0 && available < 0 ? 1 : 0};
  int nodes[2] = {0, 0};  // nodes, and nodes whose MemAvailable could not be read
  MPI_Allreduce(counts, nodes, 2, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  if (nodes[1] > 0 && world_rank == 0) {
    std::printf("warning: MemAvailable not readable on %d of %d node(s); the memory estimate (%s per rank here) is "
                "not checked there\n",
                nodes[1], nodes[0], gib_text(mine).c_str());
    std::fflush(stdout);
  }
  if (!(worst.value > 0)) return;

  double figures[4] = {need, largest, available, double(node_ranks)};
  char host[MPI_MAX_PROCESSOR_NAME] = {};
  int length = 0;
  if (world_rank == worst.rank) MPI_Get_processor_name(host, &length);
  MPI_Bcast(figures, 4, MPI_DOUBLE, worst.rank, MPI_COMM_WORLD);
  MPI_Bcast(host, MPI_MAX_PROCESSOR_NAME, MPI_CHAR, worst.rank, MPI_COMM_WORLD);
  const int ranks_there = int(figures[3]);
  const bool alike = figures[1] * ranks_there <= figures[0] * (1 + 1e-12);
  const std::string where = nodes[0] > 1 ? std::string("on node ") + host : "on this node";
  const std::string line = "the run needs " + gib_text(figures[0]) + " " + where + " (" + std::to_string(ranks_there) +
                           (ranks_there == 1 ? " rank" : " ranks") + (alike ? " x " : ", up to ") +
                           gib_text(figures[1]) + (alike ? "" : " each") + ", estimated) but " +
                           gib_text(figures[2]) + " are available (MemAvailable)";
  if (!force) throw ConfigError(line + "; --force-memory runs it anyway");
  if (world_rank == 0) {
    std::printf("warning: %s; running anyway (--force-memory)\n", line.c_str());
    std::fflush(stdout);
  }
}

void check_node_memory(const ChannelCase& c, const Int3& local, const Int3& dims, bool force) {
  // A simulated node's memory is the platform's, which names none, and the folded fields
  // take none of this machine's: MemAvailable here says nothing about it (it refused a
  // simulated 8192-rank run once the simulator itself had taken this machine's memory).
  if constexpr (kSimulated) return;
  check_node_memory(estimate_rank_memory(c, local, dims).total(), force);
}

}  // namespace efsi
