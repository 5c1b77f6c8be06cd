#pragma once
// CPU time spent inside MPI's blocking calls, for the CI gate's figure (kernel_clock.hpp).
//
// bench_kernels defines MPI_Sendrecv, MPI_Waitall, MPI_Allreduce and MPI_Alltoallv (the calls
// in which the solver waits for other ranks: the sync and async halo exchanges, the ACM and
// blow-up reductions, the FFT transposes) as thin wrappers over their PMPI_ entry points that
// add the CPU time spent inside to a counter.  A rank that waits for a peer spins inside
// them; on cores shared with other jobs it spins for as long as its peer is preempted, which
// no least-of-many-samples removes when every step waits hundreds of times (an SOR step).
// CPU time less this counter is the rank's own work: unaffected by preemption, its own or
// its peers'.
//
// Reading the CPU clock costs about 0.4 us (a system call), twice per wrapped call, which
// would show in the times of kernels that call MPI often (an SOR sweep at 32^3: about 10%).
// So the wrappers only count when the environment asks for it (EFSI_MPI_WAIT_CLOCK=1, as
// ci/microbench_gate.sh does; the gate reads CPU times only) and the kernel being timed is not
// a communication kernel (kernel_timing.hpp switches it per benchmark); otherwise they go
// straight to PMPI.
namespace efsi::bench {

// Seconds of process CPU time spent inside the wrapped calls while counting was on.
double mpi_wait_cpu_seconds();

// EFSI_MPI_WAIT_CLOCK=1 in the environment.
bool mpi_wait_clock_requested();

// Counting on or off (off at start).
void set_mpi_wait_clock(bool on);

}  // namespace efsi::bench
