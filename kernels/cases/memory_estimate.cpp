#include "memory_estimate.hpp"

#include "field.hpp"

namespace efsi {
MemoryEstimate estimate_rank_memory(const ChannelCase& c, const Int3& local, const Int3& dims) {
  ChannelCase probe = c;
  probe.domain.cells = {16, 16, 16};
  for (int a = 0; a < 3; ++a) probe.domain.length[a] = 16 * c.domain.spacing(a);
  probe.forced_dims = {1, 1, 1};
  probe.particles = 0;
  probe.slab = 0;
  CartDecomposition dec(MPI_COMM_SELF, probe.domain.cells, 1, probe.forced_dims);
  FieldRecorder recorder;
  { auto solver = build_solver(probe, dec, {}); }

  MemoryEstimate m;
  m.fields = static_cast<int>(recorder.specs().size());
  for (const FieldSpec& f : recorder.specs())
    m.field_bytes += Field::allocation_doubles(local, f.halo) * sizeof(double);
  m.solver_bytes = static_cast<std::size_t>(c.method.spec->extra_bytes(local, dims));
  return m;
}

}  // namespace efsi
