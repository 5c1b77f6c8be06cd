#pragma once
// The memory one rank needs for a channel case, known before anything of full size is
// allocated: what the strong-scaling dry run prints for thousands of ranks.
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

}  // namespace efsi
