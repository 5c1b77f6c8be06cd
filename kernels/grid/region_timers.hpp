#pragma once
// Per-rank wall-clock accumulators for the regions of docs/numerics.md, "Timer regions and the communication fraction", and their
// summary over ranks (min, mean, max; the slowest rank's elapsed time).
#include <mpi.h>

#include <array>
#include <string>
#include <string_view>

namespace efsi {

// Exclusive regions: a second of wall time lands in one at most.  The grid's own regions
// come first; a pressure method defines its own (define_region) where its code lives, so
// nothing here names a method.  Communication (the comm figure) is halo_mpi + halo_wait +
// reduce + every region defined as communication.
struct Region {
  int id;
  static const Region compute, halo_pack, halo_unpack, halo_mpi, halo_wait, reduce;
};
inline constexpr Region Region::compute{0};
inline constexpr Region Region::halo_pack{1};
inline constexpr Region Region::halo_unpack{2};
inline constexpr Region Region::halo_mpi{3};     // blocking exchanges; posting and progressing async ones
inline constexpr Region Region::halo_wait{4};    // async exchanges: the final wait, what overlap hides
inline constexpr Region Region::reduce{5};
inline constexpr int kMaxRegions = 16;

// A new region named `name` (the same program defines the same regions in the same order on
// every rank: at static initialisation of the file that uses it).  Throws std::logic_error
// past kMaxRegions.
Region define_region(std::string_view name, bool communication);
int region_count();  // defined so far
std::string_view to_string(Region r);
bool is_communication(Region r);

class RegionTimers {
 public:
  void add(Region r, double seconds) { acc_[r.id] += seconds; }
  double get(Region r) const { return acc_[r.id]; }
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
  std::array<double, kMaxRegions> acc_{};
};

struct Spread {
  double min = 0, mean = 0, max = 0;
};

struct TimerReport {
  std::array<Spread, kMaxRegions> region{};  // region_count() of them
  Spread elapsed;           // per-rank elapsed time of the measured section
  Spread comm;              // halo MPI (posting and waiting) + reductions + communication regions, per rank
  double comm_fraction = 0; // mean comm time / slowest rank's elapsed time
  const Spread& operator[](Region r) const { return region[r.id]; }
};

// Collective over `comm`: every rank receives the same report.
TimerReport summarize(const RegionTimers& timers, double elapsed, MPI_Comm comm);

}  // namespace efsi
