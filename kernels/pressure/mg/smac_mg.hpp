#pragma once
// SMAC with the multigrid Poisson solve (docs/numerics.md, "Multigrid solver"): dp solves
// Lap dp = D*/dt to a relative residual or for a fixed number of V-cycles, <dp> = 0.
#include <memory>

#include "halo_exchange.hpp"
#include "mg_poisson.hpp"
#include "pressure_method.hpp"

namespace efsi {

class SmacMgPressure final : public PressureMethod {
 public:
  explicit SmacMgPressure(const MgStop& stop) : stop_(stop) {}
  void attach(const CartDecomposition& decomp, const Domain& domain, FsiWork& work, RegionTimers& timers) override;
  void increment(PressureInputs& in) override;
  const PressureReport& report() const override { return report_; }

 private:
  MgStop stop_;
  std::unique_ptr<MgPoisson> mg_;
  std::unique_ptr<HaloExchange> dp_halo_;
  PressureReport report_;
};

}  // namespace efsi
