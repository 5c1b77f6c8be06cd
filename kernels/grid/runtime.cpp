#include "runtime.hpp"

#include <mpi.h>
#include <omp.h>

#include <cstdio>
#include <cstdlib>

#if defined(__SSE3__)
#include <pmmintrin.h>
#include <xmmintrin.h>
#endif

#include "simulation.hpp"

namespace efsi {

namespace {

// Subnormal numbers flushed to zero, as results (FTZ) and as operands (DAZ).  WENO5 spreads
// phi and Bt into the fluid as ever smaller values; once they fall below 2.2e-308 every
// operation on them takes a microcode assist, and on an Intel core the ACM step ran 1.55x
// slower from that alone (README, "Subnormal numbers").  No value that small means anything
// here, and the mode is the same on every rank and thread, so runs stay deterministic and
// sync, async and any rank grid still agree bit for bit.
void flush_subnormals_here() {
#if defined(__SSE3__)
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
#endif
}

}  // namespace

bool subnormals_flushed() {
#if defined(__SSE3__)
  return _MM_GET_FLUSH_ZERO_MODE() == _MM_FLUSH_ZERO_ON && _MM_GET_DENORMALS_ZERO_MODE() == _MM_DENORMALS_ZERO_ON;
#else
  return false;
#endif
}

Runtime::Runtime(int& argc, char**& argv, int threads) {
  // Open MPI's own MPI-IO (OMPIO) opens every file with a shared-file-pointer component:
  // the default one keeps a semaphore named after the file in /dev/shm, which a run killed
  // while writing leaves taken, so that the next open of a file of that name (a checkpoint's
  // temporary) waits forever; the others leave files beside the output when a write fails.
  // ROMIO, Open MPI's other MPI-IO, has none of this.  A user's own setting wins; other MPI
  // libraries ignore the variable.
  setenv("OMPI_MCA_io", "^ompio", 0);
  // A simulated rank (SimGrid's SMPI) is one thread: SMPI offers MPI_THREAD_SINGLE and
  // charges the time of the calling thread only.
  const int needed = kSimulated ? MPI_THREAD_SINGLE : MPI_THREAD_FUNNELED;
  MPI_Init_thread(&argc, &argv, needed, &provided_);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  if (provided_ < needed) {
    if (rank_ == 0)
      std::fprintf(stderr, "error: the MPI library gives thread level %d, below the %d this build needs\n",
                   provided_, needed);
    MPI_Abort(MPI_COMM_WORLD, 2);
  }
  set_threads(threads);
  // On the master and the pool's threads (the master is one of them); threads made later
  // start with their creator's mode.
#pragma omp parallel
  flush_subnormals_here();
}

Runtime::~Runtime() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (!finalized) MPI_Finalize();
}

void set_threads(int threads) {
  if (kSimulated) threads = 1;  // one thread a simulated rank (Runtime's constructor says why)
  if (threads > 0) omp_set_num_threads(threads);
}

int max_threads() { return omp_get_max_threads(); }

}  // namespace efsi
