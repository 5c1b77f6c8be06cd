#pragma once
// Per-rank wall-clock accumulators for the regions of DESIGN.md section 7, and their
// summary over ranks (min, mean, max; the slowest rank's elapsed time).
#include <mpi.h>

#include <array>
#include <string_view>

namespace efsi {

// Exclusive regions: a second of wall time lands in one at most.  Communication (the
// comm figure) is halo_mpi + halo_wait + reduce + transpose_mpi.
enum class Region : int {
  compute,
  halo_pack,
  halo_unpack,
  halo_mpi,       // blocking exchanges; posting and progressing the async ones
  halo_wait,      // async exchanges: the final wait, what overlap with computation hides
  reduce,
  sor_sweeps,     // SOR colour updates
  fft_solve,      // the FFT Poisson solve less its transposes: FFTs, Thomas, reordering
  transpose_mpi,  // the FFT solve's MPI_Alltoallv
  count
};
inline constexpr int kRegionCount = static_cast<int>(Region::count);

std::string_view to_string(Region r);

class RegionTimers {
 public:
  void add(Region r, double seconds) { acc_[static_cast<int>(r)] += seconds; }
  double get(Region r) const { return acc_[static_cast<int>(r)]; }
  void reset() { acc_.fill(0.0); }

  // Adds the wall time from construction to destruction to one region.
  class Scope {
   public:
    Scope(RegionTimers* t, Region r) : t_(t), r_(r), start_(t ? MPI_Wtime() : 0.0) {}
    ~Scope() {
      if (t_) t_->add(r_, MPI_Wtime() - start_);
    }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    RegionTimers* t_;
    Region r_;
    double start_;
  };

 private:
  std::array<double, kRegionCount> acc_{};
};

struct Spread {
  double min = 0, mean = 0, max = 0;
};

struct TimerReport {
  std::array<Spread, kRegionCount> region{};
  Spread elapsed;           // per-rank elapsed time of the measured section
  Spread comm;              // halo MPI (posting and waiting) + reductions + transposes, per rank
  double comm_fraction = 0; // mean comm time / slowest rank's elapsed time
  const Spread& operator[](Region r) const { return region[static_cast<int>(r)]; }
};

// Collective over `comm`: every rank receives the same report.
TimerReport summarize(const RegionTimers& timers, double elapsed, MPI_Comm comm);

}  // namespace efsi
