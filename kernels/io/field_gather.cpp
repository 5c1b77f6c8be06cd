#include "field_gather.hpp"

namespace efsi {

std::vector<double> gather_global(const Field& f, const CartDecomposition& dec) {
  const Int3 n = f.n(), g = dec.global();
  std::vector<double> mine;
  mine.reserve(static_cast<std::size_t>(product(n)) + 3);
  for (int a = 0; a < 3; ++a) mine.push_back(f.offset()[a]);
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) mine.push_back(f(i, j, k));
  const int count = static_cast<int>(mine.size());
  std::vector<double> all(dec.rank() == 0 ? static_cast<std::size_t>(count) * dec.size() : 0);
  MPI_Gather(mine.data(), count, MPI_DOUBLE, all.data(), count, MPI_DOUBLE, 0, dec.comm());
  std::vector<double> out;
  if (dec.rank() != 0) return out;
  out.assign(static_cast<std::size_t>(product(g)), 0.0);
  for (int r = 0; r < dec.size(); ++r) {
    const double* b = all.data() + static_cast<std::size_t>(r) * count;
    const int ox = int(b[0]), oy = int(b[1]), oz = int(b[2]);
    std::size_t m = 3;
    for (int k = 0; k < n[Z]; ++k)
      for (int j = 0; j < n[Y]; ++j)
        for (int i = 0; i < n[X]; ++i) out[(std::size_t(oz + k) * g[Y] + (oy + j)) * g[X] + (ox + i)] = b[m++];
  }
  return out;
}

}  // namespace efsi
