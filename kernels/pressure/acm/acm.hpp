#pragma once
// The explicit artificial-compressibility method with adaptive parameters (docs/numerics.md,
// "ACM"): dp = -beta^2 dt (gamma p + D*), beta and gamma chosen every step to
// minimise the mean square of the next divergence, from one MPI_Allreduce of 7 numbers.
#include <array>

#include "laplacian.hpp"
#include "pressure_method.hpp"

namespace efsi {

// The volume means an ACM step needs (sums over owned cells before the reduction).
struct AcmMoments {
  double A1 = 0, A2 = 0, A3 = 0, B1 = 0, B2 = 0, mean_p = 0, mean_div = 0;
};

struct AcmCoefficients {
  double a = 0, b = 0;  // a = beta^2 dt^2, b = a gamma
  enum class Branch { optimal, gamma_zero, no_update } branch = Branch::no_update;
};

// Minimiser of <(D* + a Lap D* + b Lap p)^2> subject to b >= 0, never dividing by zero.
AcmCoefficients acm_coefficients(const AcmMoments& m);

// The five means plus <p> and <D*>, reduced over ranks in one call.
AcmMoments acm_moments(const Field& div, const Field& p, const Domain& domain, MPI_Comm comm,
                       RegionTimers& timers);

class AcmPressure final : public PressureMethod {
 public:
  void increment(PressureInputs& in) override;
  const PressureReport& report() const override { return report_; }
  const AcmMoments& moments() const { return moments_; }
  const AcmCoefficients& coefficients() const { return coeff_; }

 private:
  PressureReport report_;
  AcmMoments moments_;
  AcmCoefficients coeff_;
};

}  // namespace efsi
