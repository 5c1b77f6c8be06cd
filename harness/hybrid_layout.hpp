#pragma once
// How a hybrid run sits on its machine: the OpenMP environment each rank was started
// with, the cores each rank may run on, and whether ranks x threads exceed a node's
// cores (then timings are not representative and the CSV row says so).
#include <mpi.h>

#include <string>

namespace efsi {

struct HybridLayout {
  int threads = 1;                 // OpenMP threads per rank in use
  std::string omp_num_threads;     // the variables as set at start-up ("" when unset)
  std::string omp_places, omp_proc_bind;
  // The cores of every rank in rank order: ranges within a rank joined by '+', ranks
  // separated by '/', e.g. "0/1" (one core each) or "0-3/4-7"; no commas, CSV-safe.
  std::string cores;
  bool oversubscribed = false;     // some node runs more threads than it has cores
};

// Collective over `comm`; every rank receives the same layout.
HybridLayout hybrid_layout(MPI_Comm comm, int threads);

// True when the ranks on this node times OMP threads exceed its cores. Collective.
bool node_oversubscribed(MPI_Comm comm, int threads);

}  // namespace efsi
