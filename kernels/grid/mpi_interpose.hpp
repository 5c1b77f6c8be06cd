#pragma once
// PMPI interposition, one mechanism for the whole suite.  The MPI calls that move data or
// wait (point to point, the waits and tests, the collectives) and MPI_Wtime are defined here
// as thin wrappers over their PMPI_ entry points, so that every caller goes through them:
// the solver's own exchanges and a library's (hypre's) alike.  They give
//  - the time this rank spends inside MPI (mpi_seconds): how a method whose library does
//    its own exchanges (the multigrid solve) counts that time as communication;
//  - the census of what this rank sends (MpiCensus): the same inputs send the same
//    messages on any machine, so the counted CI gate compares it exactly;
//  - a hook called on entry to and on exit from each wrapped call: the gate switches
//    callgrind's collection off inside MPI (a wait polls for as long as the peer takes).
// The object is linked wherever one of these functions is used.  The wrappers run on the
// calling thread only (MPI_THREAD_FUNNELED: the master thread).
namespace efsi {

struct MpiCensus {
  long long messages = 0;          // point-to-point sends to another rank
  long long bytes = 0;             // their payload
  long long collectives = 0;       // collective calls
  long long collective_bytes = 0;  // what this rank contributes to them (Alltoallv: to other ranks)
};

MpiCensus operator-(const MpiCensus& a, const MpiCensus& b);
MpiCensus operator+(const MpiCensus& a, const MpiCensus& b);

// This rank's census since MPI_Init.
MpiCensus mpi_census();

// Wall seconds this rank has spent inside the wrapped calls since MPI_Init (MPI_Wtime's own
// calls not included).
double mpi_seconds();

// Called on entry to and on exit from every wrapped call while set; nullptr: none.
void set_mpi_call_hook(void (*hook)());

}  // namespace efsi
