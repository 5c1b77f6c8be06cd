#pragma once
// PMPI interposition for bench_kernels.  bench_kernels defines the MPI calls the solver makes
// (point to point, the waits and tests, the collectives, MPI_Wtime) as thin wrappers over
// their PMPI_ entry points, for two figures of the counted CI gate that must not depend on
// the host or its load:
//  - the census: how many messages and bytes this rank sends (MpiCensus).  The same inputs
//    send the same messages on any machine, so the gate compares them exactly.
//  - MPI's own instructions left out of callgrind's counts (callgrind_region.hpp): a wait or
//    test polls for as long as the peer takes, so its instruction count changes with the
//    load; while a counted region is open every wrapped call switches collection off inside.
// The wrappers run on the calling thread only (MPI_THREAD_FUNNELED: the master thread).
namespace efsi::bench {

struct MpiCensus {
  long long messages = 0;          // point-to-point sends to another rank (MPI_Isend, MPI_Sendrecv)
  long long bytes = 0;             // their payload
  long long collectives = 0;       // MPI_Allreduce, MPI_Alltoallv, MPI_Bcast, MPI_Barrier calls
  long long collective_bytes = 0;  // what this rank contributes to them (Alltoallv: to other ranks)
};

MpiCensus operator-(const MpiCensus& a, const MpiCensus& b);

// This rank's census since MPI_Init.
MpiCensus mpi_census();

// While on, each wrapped call is taken out of callgrind's event collection (the call
// switches collection off on entry and back on at exit).  Off at start.
void set_mpi_uncollected(bool on);

}  // namespace efsi::bench
