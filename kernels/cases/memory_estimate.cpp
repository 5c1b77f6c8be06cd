#include "memory_estimate.hpp"

#include "field.hpp"

namespace efsi {
namespace {

// FftPoisson per cell of the block, in 8-byte words (fft_poisson.cpp): the block, x-pencil,
// r2c output, z-pencil and y-pencil buffers (5); the real x transpose's send and receive
// buffers and int64 index lists (4); the two complex transposes, half the points as
// complex numbers: buffers 2 x 1 and index lists 2 x 1/2 each (3 + 3).
constexpr double kFftWordsPerCell = 15.0;

}  // namespace

MemoryEstimate estimate_rank_memory(const ChannelCase& c, const Int3& local) {
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
  if (c.method == PressureKind::fft)
    m.solver_bytes = static_cast<std::size_t>(kFftWordsPerCell * double(product(local)) * 8.0);
  return m;
}

}  // namespace efsi
