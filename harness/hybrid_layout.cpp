#include "hybrid_layout.hpp"

#include <sched.h>
#include <unistd.h>

#include <cstdlib>
#include <vector>

namespace efsi {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  std::string s = v ? v : "";
  for (char& c : s)
    if (c == ',') c = ';';  // OMP_PLACES "{0},{1}" must not split a CSV cell
  return s;
}

// The cores this rank's OpenMP threads may run on, as ranges, e.g. "0-3+8": the union of
// the threads' masks, since with OMP_PROC_BIND each thread (the initial one too) is pinned
// to its own place and no single thread's mask shows the rank's cores.
std::string my_cores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  bool ok = true;
#pragma omp parallel
  {
    cpu_set_t mine;
    CPU_ZERO(&mine);
    const bool got = sched_getaffinity(0, sizeof mine, &mine) == 0;
#pragma omp critical(efsi_hybrid_layout)
    {
      ok = ok && got;
      CPU_OR(&set, &set, &mine);
    }
  }
  if (!ok) return "?";
  std::string out;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (!CPU_ISSET(c, &set)) continue;
    int last = c;
    while (last + 1 < CPU_SETSIZE && CPU_ISSET(last + 1, &set)) ++last;
    if (!out.empty()) out += '+';
    out += std::to_string(c);
    if (last > c) out += '-' + std::to_string(last);
    c = last;
  }
  return out;
}

}  // namespace

bool node_oversubscribed(MPI_Comm comm, int threads) {
  MPI_Comm node;
  MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int local = 1;
  MPI_Comm_size(node, &local);
  MPI_Comm_free(&node);
  const long cores = sysconf(_SC_NPROCESSORS_ONLN);
  const int mine = long(local) * threads > cores ? 1 : 0;
  int any = 0;
  MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, comm);
  return any != 0;
}

HybridLayout hybrid_layout(MPI_Comm comm, int threads) {
  HybridLayout h;
  h.threads = threads;
  h.omp_num_threads = env("OMP_NUM_THREADS");
  h.omp_places = env("OMP_PLACES");
  h.omp_proc_bind = env("OMP_PROC_BIND");
  h.oversubscribed = node_oversubscribed(comm, threads);

  // Every rank's core list, gathered everywhere so that all ranks hold the same layout.
  const std::string mine = my_cores();
  int size = 1;
  MPI_Comm_size(comm, &size);
  const int len = static_cast<int>(mine.size());
  std::vector<int> lens(size), displs(size);
  MPI_Allgather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, comm);
  int total = 0;
  for (int r = 0; r < size; ++r) displs[r] = total, total += lens[r];
  std::string all(static_cast<std::size_t>(total), ' ');
  MPI_Allgatherv(mine.data(), len, MPI_CHAR, all.data(), lens.data(), displs.data(), MPI_CHAR, comm);
  for (int r = 0; r < size; ++r) {
    if (r > 0) h.cores += '/';
    h.cores.append(all, static_cast<std::size_t>(displs[r]), static_cast<std::size_t>(lens[r]));
  }
  return h;
}

}  // namespace efsi
