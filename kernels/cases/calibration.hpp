#pragma once
// The paper's calibration of an iteration count per step (SOR's N_S, MG's V-cycles; the
// paper gave N_S on its weak-scaling block, paper_constants.hpp; the methods use their
// calibrated counts when none is given).
//
// The state calibrated on: the case's solid (for the weak block, its 2 biconcave
// particles) at rest and unstrained in the steady laminar Poiseuille flow of the driving
// force, advanced `warmup` steps with the exact FFT SMAC (so that the particles have
// started to deform and the pressure has developed), on one rank.  The right-hand side is
// D*/dt of the next step; the method iterates from dp = 0, as every one of its steps does,
// and counts iterations until the residual is at most eps times its initial value.
#include <cstddef>
#include <vector>

#include "channel_case.hpp"

namespace efsi {

struct Calibration {
  std::vector<int> iterations;     // per requested eps; -1: not reached within max_iterations
  std::vector<double> history;     // relative residual after each iteration
  double initial_residual = 0.0;   // RMS of D*/dt
  double fft_difference = 0.0;     // max |dp - dp_fft| / max |dp_fft| after the last iteration
};

// Collective; meant for one rank (the paper's procedure), works on any.  c.method names
// the method calibrated, which must have a calibrated count (MethodSpec::calibrated_count);
// the warm-up uses the FFT reference with c.solver's stress scheme.
Calibration calibrate(const ChannelCase& c, const CartDecomposition& decomp, const std::vector<Particle>& particles,
                      long warmup, const std::vector<double>& eps, int max_iterations);

// The bytes one rank holds in calibrate on `local` cells of the `dims` rank grid: the FFT
// reference solver and the calibrated method's memory beyond its fields (MG: hypre's). The
// counter's own iterate (one field, SOR) is small beside the solver's and left out.
std::size_t calibration_memory(const ChannelCase& c, const Int3& local, const Int3& dims);

}  // namespace efsi
