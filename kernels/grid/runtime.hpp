#pragma once
// MPI and OpenMP start-up for every executable: MPI_Init_thread with at least
// MPI_THREAD_FUNNELED (only the master thread calls MPI; grid loops are OpenMP), and
// subnormal numbers flushed to zero on every thread (runtime.cpp).
namespace efsi {

class Runtime {
 public:
  // threads > 0 overrides OMP_NUM_THREADS.
  Runtime(int& argc, char**& argv, int threads = 0);
  ~Runtime();
  Runtime(const Runtime&) = delete;
  Runtime& operator=(const Runtime&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  int thread_level() const { return provided_; }

 private:
  int rank_ = 0;
  int size_ = 1;
  int provided_ = 0;
};

// Whether the calling thread flushes subnormal results and operands to zero (x86 only).
bool subnormals_flushed();

// Sets the OpenMP thread count of later parallel regions; threads <= 0 leaves it as is.
void set_threads(int threads);
int max_threads();

}  // namespace efsi
