#pragma once
// The two SMAC pressure corrections (DESIGN.md 3.2 and 3.3): dp solves the discrete
// Poisson equation Lap dp = D*/dt, so that D^{N+1} = D* - dt Lap dp is what the solve
// leaves of its residual (dt times it).
//   fft: exactly (FFTW along x and z, Thomas along y); <dp> = 0.
//   sor: N_S four-colour SOR sweeps (omega 1.6) from dp = 0 each step, so that the
//        residual ratio eps of the calibration is also the factor by which the step
//        reduces the divergence; no global reduction at all (the mean of p is left free).
#include <memory>

#include "fft_poisson.hpp"
#include "halo_exchange.hpp"
#include "pressure_method.hpp"
#include "sor_poisson.hpp"

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

class SmacSorPressure final : public PressureMethod {
 public:
  // sweeps: N_S per step (>= 1).
  SmacSorPressure(SorComm comm, int sweeps, double omega = 1.6);
  void attach(const CartDecomposition& decomp, const Domain& domain, FsiWork& work, RegionTimers& timers) override;
  void increment(PressureInputs& in) override;
  const PressureReport& report() const override { return report_; }
  int sweeps() const { return sweeps_; }

 private:
  SorComm comm_;
  int sweeps_;
  double omega_;
  std::unique_ptr<SorPoisson> sor_;
  PressureReport report_;
};

// The paper's calibration of N_S (section 3.2): SOR sweeps from x = 0 on Lap x = factor
// rhs until the RMS residual is at most eps times its initial value. Returns the count,
// or -1 when max_sweeps did not get there. `residuals` (optional) receives the relative
// residual after every sweep. Collective; x is overwritten.
int count_sor_sweeps(SorPoisson& sor, Field& x, const Field& rhs, double factor, double eps, int max_sweeps,
                     std::vector<double>* residuals = nullptr);

}  // namespace efsi
