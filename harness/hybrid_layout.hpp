#pragma once
// How a hybrid run sits on its machine: the OpenMP environment each rank was started
// with, the cores the ranks may run on, and whether ranks x threads exceed a node's
// cores (then timings are not representative and the CSV row says so).  Every summary
// here has a size bounded independently of the rank count: at the paper's 8192 ranks
// the banner stays one short line.
#include <mpi.h>

#include <string>

namespace efsi {

struct HybridLayout {
  int threads = 1;                 // OpenMP threads per rank in use
  std::string omp_num_threads;     // the variables as set at start-up ("" when unset)
  std::string omp_places, omp_proc_bind;
  // The distinct core sets the ranks may run on, each with its rank count, in the order of
  // the first rank that has it: ranges joined by '+', the count after '*', entries by '/';
  // e.g. "0*1/1*1" (two ranks, one core each) or "0-1*64" (64 ranks on both cores).  At
  // most kMaxBindings entries, then "other*N" for the ranks left.  No commas: CSV-safe.
  // "simulated" in the simulation build, whose ranks all run in one process.
  std::string cores;
  bool cores_shared = false;       // two ranks on one node may run on a common core
  bool oversubscribed = false;     // some node runs more threads than it has cores (simulated:
                                   // the platform host's cores)
};

inline constexpr int kMaxBindings = 16;

// Collective over `comm` (reductions only, no gather); every rank receives the same layout.
HybridLayout hybrid_layout(MPI_Comm comm, int threads);

}  // namespace efsi
