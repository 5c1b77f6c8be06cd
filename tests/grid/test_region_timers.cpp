// Region timers summarised over ranks: min, mean and max, the slowest rank's elapsed
// time, and the communication fraction = mean (halo MPI + halo wait + reduce + the regions defined as communication) / max elapsed.
#include <gtest/gtest.h>
#include <mpi.h>

#include "region_timers.hpp"

using namespace efsi;

TEST(RegionTimers, SummaryOverRanks) {
  int rank = 0, p = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &p);
  RegionTimers t;
  t.add(Region::compute, 10.0 * (rank + 1));
  t.add(Region::halo_mpi, 1.0 * (rank + 1));
  t.add(Region::reduce, 0.5);
  t.add(Region::halo_mpi, 1.0);  // accumulates
  const double elapsed = 12.0 * (rank + 1) + 0.5;

  const TimerReport r = summarize(t, elapsed, MPI_COMM_WORLD);
  EXPECT_DOUBLE_EQ(r[Region::compute].min, 10.0);
  EXPECT_DOUBLE_EQ(r[Region::compute].max, 10.0 * p);
  EXPECT_DOUBLE_EQ(r[Region::compute].mean, 10.0 * (p + 1) / 2.0);
  EXPECT_DOUBLE_EQ(r[Region::halo_mpi].mean, (p + 1) / 2.0 + 1.0);
  EXPECT_DOUBLE_EQ(r.elapsed.max, 12.0 * p + 0.5);
  EXPECT_DOUBLE_EQ(r.comm.min, 1.0 + 1.0 + 0.5);
  EXPECT_DOUBLE_EQ(r.comm.max, p + 1.0 + 0.5);
  EXPECT_DOUBLE_EQ(r.comm_fraction, ((p + 1) / 2.0 + 1.5) / (12.0 * p + 0.5));
  EXPECT_GT(r.comm_fraction, 0.0);
  EXPECT_LT(r.comm_fraction, 1.0);
}

TEST(RegionTimers, ScopeAddsElapsedWallTime) {
  RegionTimers t;
  const double t0 = MPI_Wtime();
  {
    RegionTimers::Scope s(&t, Region::reduce);
    const double s0 = MPI_Wtime();  // after the scope started
    while (MPI_Wtime() - s0 < 0.02) {
    }
  }
  const double outer = MPI_Wtime() - t0;
  EXPECT_GE(t.get(Region::reduce), 0.02);
  EXPECT_LE(t.get(Region::reduce), outer);
  EXPECT_EQ(t.get(Region::compute), 0.0);
}
