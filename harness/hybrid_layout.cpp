#include "hybrid_layout.hpp"

#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "compute_model.hpp"

namespace efsi {
namespace {

std::string env(const char* name) {
  const char* v = std::getenv(name);
  std::string s = v ? v : "";
  for (char& c : s)
    if (c == ',') c = ';';  // OMP_PLACES "{0},{1}" must not split a CSV cell
  return s;
}

// The cores this rank's OpenMP threads may run on: the union of the threads' masks, since
// with OMP_PROC_BIND each thread (the initial one too) is pinned to its own place and no
// single thread's mask shows the rank's cores.  False when a mask could not be read.
bool my_cores(cpu_set_t& set) {
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
  return ok;
}

// "0-3+8": the set as ranges.
std::string ranges(const cpu_set_t& set) {
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
  return out.empty() ? "?" : out;  // an empty set: the mask could not be read
}

// The distinct bindings of a group of ranks, merged pairwise up a reduction tree: its size
// is fixed, whatever the rank count.
struct Bindings {
  struct Entry {
    cpu_set_t set;
    std::int64_t ranks;
    std::int64_t first_rank;
  };
  std::int64_t used = 0;
  std::int64_t other = 0;  // ranks whose binding found no free entry
  Entry entry[kMaxBindings];

  void add(const Entry& e) {
    for (std::int64_t i = 0; i < used; ++i)
      if (CPU_EQUAL(&entry[i].set, &e.set)) {
        entry[i].ranks += e.ranks;
        entry[i].first_rank = std::min(entry[i].first_rank, e.first_rank);
        return;
      }
    if (used < kMaxBindings) entry[used++] = e;
    else other += e.ranks;
  }
};

void merge_bindings(void* in, void* inout, int* len, MPI_Datatype*) {
  auto* a = static_cast<const Bindings*>(in);
  auto* b = static_cast<Bindings*>(inout);
  for (int n = 0; n < *len; ++n) {
    for (std::int64_t i = 0; i < a[n].used; ++i) b[n].add(a[n].entry[i]);
    b[n].other += a[n].other;
  }
}

// The summary on rank 0 of `comm` ("" elsewhere).  Reduced, not gathered: with more
// distinct bindings than entries, which ones get an entry depends on the tree's order.
std::string binding_summary(MPI_Comm comm, const cpu_set_t& mine, bool readable) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  Bindings local{};
  Bindings::Entry e{};
  e.set = mine;
  if (!readable) CPU_ZERO(&e.set);
  e.ranks = 1;
  e.first_rank = rank;
  local.add(e);
  MPI_Datatype type;
  MPI_Type_contiguous(static_cast<int>(sizeof(Bindings)), MPI_BYTE, &type);
  MPI_Type_commit(&type);
  MPI_Op op;
  MPI_Op_create(&merge_bindings, 1, &op);
  Bindings all{};
  MPI_Reduce(&local, &all, 1, type, op, 0, comm);
  MPI_Op_free(&op);
  MPI_Type_free(&type);
  if (rank != 0) return {};
  std::sort(all.entry, all.entry + all.used,
            [](const Bindings::Entry& x, const Bindings::Entry& y) { return x.first_rank < y.first_rank; });
  std::string out;
  for (std::int64_t i = 0; i < all.used; ++i) {
    if (i > 0) out += '/';
    out += ranges(all.entry[i].set);
    out += '*';
    out += std::to_string(all.entry[i].ranks);
  }
  if (all.other > 0) out += "/other*" + std::to_string(all.other);
  return out;
}

// Whether two ranks of one node may run on a common core, and whether the node's ranks x
// threads exceed its cores: counted on the node (the masks summed core by core), then the
// worst node's answer everywhere.
void node_checks(MPI_Comm comm, const cpu_set_t& mine, int threads, HybridLayout& h) {
  MPI_Comm node;
  MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  int local = 1;
  MPI_Comm_size(node, &local);
  std::vector<int> mine_count(CPU_SETSIZE), on_node(CPU_SETSIZE);
  for (int c = 0; c < CPU_SETSIZE; ++c) mine_count[c] = CPU_ISSET(c, &mine) ? 1 : 0;
  MPI_Allreduce(mine_count.data(), on_node.data(), CPU_SETSIZE, MPI_INT, MPI_SUM, node);
  MPI_Comm_free(&node);
  // A simulated node has the platform host's cores, not this machine's.
  const long cores = kSimulated ? node_model().cores_on_node : sysconf(_SC_NPROCESSORS_ONLN);
  int flags[2] = {long(local) * threads > cores ? 1 : 0,
                  std::any_of(on_node.begin(), on_node.end(), [](int n) { return n > 1; }) ? 1 : 0};
  MPI_Allreduce(MPI_IN_PLACE, flags, 2, MPI_INT, MPI_MAX, comm);
  h.oversubscribed = flags[0] != 0;
  h.cores_shared = flags[1] != 0;
}

}  // namespace

HybridLayout hybrid_layout(MPI_Comm comm, int threads) {
  HybridLayout h;
  h.threads = threads;
  h.omp_num_threads = env("OMP_NUM_THREADS");
  h.omp_places = env("OMP_PLACES");
  h.omp_proc_bind = env("OMP_PROC_BIND");
  cpu_set_t mine;
  const bool readable = my_cores(mine);
  node_checks(comm, mine, threads, h);
  if (kSimulated) {  // every simulated rank runs in this one process: its mask says nothing
    h.cores = "simulated";
    h.cores_shared = false;
    return h;
  }
  h.cores = binding_summary(comm, mine, readable);
  int len = static_cast<int>(h.cores.size());
  MPI_Bcast(&len, 1, MPI_INT, 0, comm);
  h.cores.resize(static_cast<std::size_t>(len));
  MPI_Bcast(h.cores.data(), len, MPI_CHAR, 0, comm);
  return h;
}

}  // namespace efsi
