#pragma once
// SMAC with the exact Poisson solve (docs/numerics.md, "SMAC"): dp solves Lap dp = D*/dt
// exactly (FFTW along x and z, Thomas along y), <dp> = 0.  The accuracy reference.
#include <memory>

#include "fft_poisson.hpp"
#include "halo_exchange.hpp"
#include "pressure_method.hpp"

namespace efsi {

class SmacFftPressure final : public PressureMethod {
 public:
  explicit SmacFftPressure(FftPoisson::Planning planning = FftPoisson::Planning::measure) : planning_(planning) {}
  void attach(const CartDecomposition& decomp, const Domain& domain, FsiWork& work, RegionTimers& timers) override;
  void increment(PressureInputs& in) override;
  const PressureReport& report() const override { return report_; }

 private:
  FftPoisson::Planning planning_;
  std::unique_ptr<FftPoisson> fft_;
  std::unique_ptr<HaloExchange> dp_halo_;
  PressureReport report_;
};

}  // namespace efsi
