#pragma once
// SMAC with four-colour SOR (docs/numerics.md, "SMAC"): N_S sweeps (omega 1.6) of
// Lap dp = D*/dt from dp = 0 each step, so that the residual ratio eps of the calibration
// is also the factor by which the step reduces the divergence; no global reduction at all
// (the mean of p is left free).
#include <memory>
#include <string>
#include <vector>

#include "paper_constants.hpp"
#include "pressure_method.hpp"
#include "sor_poisson.hpp"

namespace efsi {

// N_S, the sweeps per step, is at least 1; throws ConfigError naming `what` ("--ns") otherwise.
void check_sor_sweeps(double sweeps, const std::string& what);

class SmacSorPressure final : public PressureMethod {
 public:
  // sweeps: N_S per step (>= 1); sweeps_per_exchange and halo: SorPoisson's.
  SmacSorPressure(CommMode comm, int sweeps, double omega = paper::kSorOmega, int sweeps_per_exchange = 1,
                  HaloPattern halo = HaloPattern::direct);
  void attach(const CartDecomposition& decomp, const Domain& domain, FsiWork& work, RegionTimers& timers) override;
  void increment(PressureInputs& in) override;
  const PressureReport& report() const override { return report_; }
  int sweeps() const { return sweeps_; }

 private:
  CommMode comm_;
  int sweeps_;
  double omega_;
  int sweeps_per_exchange_;
  HaloPattern halo_;
  std::unique_ptr<SorPoisson> sor_;
  PressureReport report_;
};

}  // namespace efsi
