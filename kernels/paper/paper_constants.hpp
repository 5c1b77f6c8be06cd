#pragma once
// The paper's constants in one place (Sugiyama et al., HPCS 2012; docs/numerics.md,
// "Experiments"), and the SOR sweep counts our calibration of its procedure gave.
// Everything that defaults to one of these reads it from here.
namespace efsi::paper {

// The weak-scaling block: 64^3 cells on a 3.6^3 box per rank, one particle-lattice cell
// holding two biconcave particles.
inline constexpr int kBlockCells = 64;
inline constexpr double kBlockLength = 3.6;
inline constexpr double kSpacing = kBlockLength / kBlockCells;
inline constexpr int kParticlesPerBlock = 2;
inline constexpr double kShearModulus = 50.0;  // G

// The strong-scaling case: 2048 x 1024 x 1024 cells (16384 particles at the block's density).
inline constexpr int kStrongCells[3] = {2048, 1024, 1024};

// Time steps and measured steps of the scaling runs: the same simulated time, 6.25e-4.
inline constexpr double kAcmDt = 1.25e-5;
inline constexpr long kAcmSteps = 50;
inline constexpr double kSmacDt = 6.25e-5;
inline constexpr long kSmacSteps = 10;

// SMAC with SOR: over-relaxation, Crank-Nicolson sweeps per step, and the sweeps per step
// that reach the residual ratio eps on the block (our calibration, on the dev machine:
// `channel --cells 64 --length 3.6 --method sor --calibrate --dt 6.25e-5 --steps 200`;
// the paper's own counts were 100 and 220).
inline constexpr double kSorOmega = 1.6;
inline constexpr int kCnSweeps = 20;
struct CalibratedSweeps {
  double eps;
  int sweeps;
};
inline constexpr CalibratedSweeps kCalibratedSorSweeps[] = {{1e-3, 213}, {1e-4, 353}};
inline constexpr double kDefaultSorEps = 1e-3;

// The accuracy case: 128^3 cells on a 7.2^3 box, 16 particles, G = 50, dt = 5e-4 to t = 20.
inline constexpr int kAccuracyCells = 128;
inline constexpr double kAccuracyLength = 7.2;
inline constexpr int kAccuracyParticles = 16;
inline constexpr double kAccuracyDt = 5e-4;
inline constexpr double kAccuracyEnd = 20.0;

}  // namespace efsi::paper
