#pragma once
// The memory one rank needs for a channel case, known before anything of full size is
// allocated: what the strong-scaling dry run prints for thousands of ranks, and what a run
// checks against the node's available memory before it allocates.
#include <cstddef>

#include "channel_case.hpp"

namespace efsi {

struct MemoryEstimate {
  int fields = 0;                // Field arrays the solver makes (state, work, method, CN)
  std::size_t field_bytes = 0;   // their allocation at the target local block, padding included
  std::size_t solver_bytes = 0;  // the method's memory beyond its Fields (FFT: pencils, buffers, index lists)
  std::size_t total() const { return field_bytes + solver_bytes; }
};

// Builds the case's solver once on a 16^3 block on this process alone, with a
// FieldRecorder, to learn every field it makes (one source of truth: the constructors),
// then sizes them for `local`; the method adds its own for the `dims` rank grid. Halo
// buffers, particle lists and MPI's own memory are surface-sized or small and not counted.
// Not collective.
MemoryEstimate estimate_rank_memory(const ChannelCase& c, const Int3& local, const Int3& dims);

// Bytes in GiB, as the dry run and the memory check print them.
double gib(double bytes);

// Collective over MPI_COMM_WORLD. Sums `rank_bytes` over the ranks that share this node
// (MPI_COMM_TYPE_SHARED) and compares the sum with the node's MemAvailable
// (/proc/meminfo): a run above it would be killed by the OOM killer, or swap, hours into a
// queue slot. Every rank takes the decision of the node shortest of memory, so all throw
// ConfigError alike (one line: both figures and --force-memory), or none does. With
// `force`, rank 0 prints that line as a warning instead. Where MemAvailable cannot be read
// (no /proc, a kernel before 3.14) nothing is refused and rank 0 prints a one-line warning.
void check_node_memory(std::size_t rank_bytes, bool force);

// The same for the case's solver on `local` cells per rank of the `dims` rank grid; nothing
// in the simulation build.
void check_node_memory(const ChannelCase& c, const Int3& local, const Int3& dims, bool force);

}  // namespace efsi
