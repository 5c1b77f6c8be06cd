#include "storage.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <new>

#include "simulation.hpp"

#ifdef EFSI_SIMGRID
#include <smpi/smpi.h>
#endif

namespace efsi {
namespace {

std::size_t round_up_64(std::size_t bytes) { return (bytes + 63) / 64 * 64; }

}  // namespace

void StorageFree::operator()(double* p) const noexcept {
#ifdef EFSI_SIMGRID
  SMPI_SHARED_FREE(p);
#else
  std::free(p);
#endif
}

Storage allocate_storage(std::size_t doubles, bool zero) {
  const std::size_t bytes = round_up_64(std::max<std::size_t>(doubles, 1) * sizeof(double));
#ifdef EFSI_SIMGRID
  (void)zero;
  void* p = SMPI_SHARED_MALLOC(bytes);
  if (!p) throw std::bad_alloc();
  return Storage(static_cast<double*>(p));
#else
  void* p = std::aligned_alloc(64, bytes);
  if (!p) throw std::bad_alloc();
  if (zero) std::memset(p, 0, bytes);
  return Storage(static_cast<double*>(p));
#endif
}

}  // namespace efsi
