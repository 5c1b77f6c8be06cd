// One rank's failure made every rank's: the lowest failing rank's reason reaches all ranks,
// whole and alike; no failure gives an empty reason everywhere.
#include <gtest/gtest.h>
#include <mpi.h>

#include <string>

#include "first_failure.hpp"

using namespace efsi;

TEST(FirstFailure, NoneFailedGivesNothing) {
  EXPECT_EQ(first_failure(MPI_COMM_WORLD, ""), "");
}

TEST(FirstFailure, TheLowestFailingRanksReasonReachesEveryRank) {
  int rank = 0, p = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &p);
  // The odd ranks fail (rank 0 alone on one rank), each with a reason of its own length.
  const int lowest = p > 1 ? 1 : 0;
  const bool fails = p > 1 ? rank % 2 == 1 : true;
  const auto reason = [](int r) { return "rank " + std::to_string(r) + " failed: " + std::string(r + 3, 'x'); };
  EXPECT_EQ(first_failure(MPI_COMM_WORLD, fails ? reason(rank) : ""), reason(lowest));
}
