#pragma once
// Arrays of doubles for fields and halo buffers: 64-byte aligned.  In the simulation build
// (simulation.hpp) every simulated rank's arrays share the same pages (SMPI's folded
// memory): no stage reads their values there (compute_model.hpp), and 8192 ranks of the
// paper's 64^3 block then fit in one machine.  Folded arrays are not initialised.
#include <cstddef>
#include <memory>

namespace efsi {

struct StorageFree {
  void operator()(double* p) const noexcept;
};
using Storage = std::unique_ptr<double[], StorageFree>;

// `doubles` values (std::bad_alloc when none can be had); with `zero`, zeroed in the real
// build.  A field zeroes its own, in parallel, so that each thread first touches its part.
Storage allocate_storage(std::size_t doubles, bool zero);

}  // namespace efsi
