#pragma once
// The paper's calibration of the SOR sweep count N_S (the counts it gave on the paper's
// weak-scaling block are in paper_constants.hpp; the drivers use them when --ns is not given).
//
// The state calibrated on: the case's solid (for the weak block, its 2 biconcave
// particles) at rest and unstrained in the steady laminar Poiseuille flow of the driving
// force, advanced `warmup` steps with the exact FFT SMAC (so that the particles have
// started to deform and the pressure has developed), on one rank.  The right-hand side is
// D*/dt of the next step; SOR starts from dp = 0, as every SMAC-SOR step does, and counts
// sweeps until the RMS residual is at most eps times its initial value.
#include <vector>

#include "channel_case.hpp"

namespace efsi {

struct SorCalibration {
  std::vector<int> sweeps;         // per requested eps; -1: not reached within max_sweeps
  std::vector<double> history;     // relative RMS residual after each sweep
  double initial_residual = 0.0;   // RMS of D*/dt
  double fft_difference = 0.0;     // max |dp_sor - dp_fft| / max |dp_fft| after the last sweep
};

// Collective; meant for one rank (the paper's procedure), works on any.  c.method is
// ignored (the warm-up uses the FFT reference with c.solver's stress scheme).
SorCalibration calibrate_sor(const ChannelCase& c, const CartDecomposition& decomp,
                             const std::vector<Particle>& particles, long warmup, const std::vector<double>& eps,
                             int max_sweeps);

}  // namespace efsi
