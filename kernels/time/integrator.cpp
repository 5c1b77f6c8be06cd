#include "integrator.hpp"

#include "config_error.hpp"

namespace efsi {

const std::vector<Integrator>& integrators() {
  static const std::vector<Integrator> all{
      {"euler", "explicit Euler", {{0.0, 1.0}}, 1},
      {"rk3", "SSP-RK3 (Shu-Osher)", {{0.0, 1.0}, {0.75, 0.25}, {1.0 / 3.0, 2.0 / 3.0}}, 3},
  };
  return all;
}

const Integrator& find_integrator(const std::string& name) {
  std::string names;
  for (const Integrator& i : integrators()) {
    if (i.name == name) return i;
    names += (names.empty() ? "" : ", ") + i.name;
  }
  throw ConfigError("unknown integrator '" + name + "': expected one of " + names);
}

void blend(Field& q, const Field& q0, const IntegratorStage& stage) {
  if (stage.alpha == 0.0 && stage.beta == 1.0) return;
  const double a = stage.alpha, b = stage.beta;
  const int nx = q.owned_end(X), ny = q.owned_end(Y), nz = q.owned_end(Z);
#pragma omp parallel for collapse(2) schedule(static)
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
#pragma omp simd
      for (int i = 0; i < nx; ++i) q(i, j, k) = a * q0(i, j, k) + b * q(i, j, k);
}

}  // namespace efsi
