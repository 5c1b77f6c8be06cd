#pragma once
// Bytes and flops per owned cell of the kernels bench_kernels times, counted from the code.
//
// Conventions (the same for every kernel):
//   bytes  what the kernel must move between memory and the core: every array it reads
//          read once, every array it writes written once, 8 bytes per double per owned cell
//          (ghost points not counted; no write-allocate read, as STREAM counts its triad);
//          a kernel made of separate passes (SOR colours, FFT stages) moves its data once
//          per pass.
//   flops  + - * / and sqrt, 1 each, as written in the source for one output point, with no
//          sharing between points or between terms (the compiler may share some); max, abs
//          and the upwind selects are not counted; an average of m points costs m - 1 adds
//          and one multiply (none when m = 1).
#include <cmath>

namespace efsi::bench {

struct PerCell {
  double bytes, flops;
};
constexpr PerCell operator+(PerCell a, PerCell b) { return {a.bytes + b.bytes, a.flops + b.flops}; }
constexpr PerCell operator*(double s, PerCell a) { return {s * a.bytes, s * a.flops}; }

// compute_stress (fsi_equations.cpp stress_component, constitutive.hpp), six components:
//   reads u, v, w, phi, Bt11..Bt23 (10 arrays), writes tau11..tau23 (6): 16 x 8 = 128 B.
//   diagonal tau_AA = 2mu dv_A/dx_A + G sqrt(phi)(Bt_AA - tr/3):
//     difference 2 (sub, mul); tr 2 adds, sqrt 1, tr/3 1, Bt - 1, sqrt * 1; 2mu*, G*, + 3
//     = 2 + 6 + 3 = 11, three of them: 33
//   off-diagonal tau_AB = 2mu 0.5 (dv_A/dx_B + dv_B/dx_A) + G avg4(sqrt phi) Bt_AB:
//     strain 2 + 2 + add + 0.5* = 6; average of 4 sqrt(phi): 4 sqrt + 3 adds + 1 mul = 8,
//     times Bt 1; 2mu*, G*, + 3: 6 + 9 + 3 = 18, three of them: 54
//   total 87 flops.
inline constexpr PerCell kStress{128, 87};

// compute_vstar, the momentum right-hand side (vstar_component), three face components:
//   reads u, v, w, p, tau11..tau23 (10), writes u*, v*, w* (3): 13 x 8 = 104 B.
//   per component C: three skew-symmetric advection terms, each two flux velocities
//   (add, mul: 2 each) and 0.5 h^-1 (up uc - lo uc) (mul, 2 mul, sub, mul: 5) = 9, summed
//   (2 adds): 29; three stress-divergence terms (sub, mul: 2 each) summed: 8; grad p 2;
//   uc + dt (-adv + (div tau - grad p)/rho + f): 6.  29 + 8 + 2 + 6 = 45, three: 135 flops.
inline constexpr PerCell kMomentum{104, 135};

// compute_transport, WENO5 advection of phi and the six Bt components with the
// upper-convected stretching of Bt (transport_component, weno5.hpp):
//   reads u, v, w, phi, Bt11..Bt23 (10), writes phi_new, Bt_new (7): 17 x 8 = 136 B.
//   weno5_derivative: 5 quotients (sub, mul) 10; weno5_upwind: candidates 5 + 4 + 4,
//   indicators' differences 3 + 4 + 3 + 1 + 3 + 4, s_k 6 each, squares 3, alpha 6, final
//   (3 mul, 2 add, 2 add, mul, div) 9: 67; so 77.  One advection v_M dq/dx_M = average of
//   v_M to q's location (2 points: 2 flops, or 8 points: 8 for an edge component along its
//   unstaggered axis) + 77 + 1 (v *): 80 or 86.
//   phi: 3 x 80 + 2 adds + phi - dt adv (2) = 244.
//   Bt_AB: 3 advections (240 for diagonal, 80 + 80 + 86 = 246 for edge components) + 2 adds;
//   stretching sum_M L_AM Bt_MB + Bt_AM L_BM, each factor averaged to Bt_AB's location
//   (gradient 2 flops per sample): 7 + 35 + 35 = 77 (diagonal) or 21 + 21 + 35 = 77 (edge),
//   + 2 adds; Bt + dt (uc - adv) 3.  Diagonal 240 + 2 + 77 + 2 + 3 = 324, edge 330.
//   total 244 + 3 x 324 + 3 x 330 = 2206 flops.
inline constexpr PerCell kTransport{136, 2206};

// add_stretching (Crank-Nicolson): the stretching part of the above on base:
//   reads u, v, w, Bt (6), base (6), writes out (6): 21 x 8 = 168 B; per component
//   77 + 2 adds + base + dt uc (2) = 81, six: 486 flops.
inline constexpr PerCell kStretching{168, 486};

// add_stress_divergence_difference: reads tau_a, tau_b (12), base (3), writes out (3):
//   18 x 8 = 144 B; per face component 2 x (3 x 2 + 2) + sub + c* + add = 19, three: 57.
inline constexpr PerCell kStressDivergenceDifference{144, 57};

// FsiSolver::compute_divergence: reads u*, v*, w*, writes div: 32 B; 3 x (sub, mul) + 2 = 8.
inline constexpr PerCell kDivergence{32, 8};

// FsiSolver::project: reads p, dp, u*, v*, w*, writes p, u, v, w: 72 B;
//   p += dp 1, each velocity u* - c (dp - dp_low) 3: 10 flops.
inline constexpr PerCell kProject{72, 10};

// acm_moments, the local sums before the one MPI_Allreduce of 7 doubles: reads div and p:
//   16 B; two 7-point Laplacians ((a - 2c + b) h^-2: 4 per axis, 2 adds: 14 each) 28,
//   five products accumulated (2 each) 10, two sums 2: 40 flops.
inline constexpr PerCell kAcmMoments{16, 40};

// AcmPressure::increment = acm_moments + the update dp = -(b p + a div)/dt - shift:
//   the update reads p, div, writes dp: 24 B; 2 mul, add, div, sub: 5 flops.
inline constexpr PerCell kAcmUpdate{24, 5};

// One four-colour SOR sweep (SorPoisson::update): each colour is a separate pass (it reads
//   the colours before it) that reads all of x (the neighbours are the other colours),
//   reads rhs on its rows (half of them: 4 B per cell) and writes x on its rows (4 B):
//   16 B per colour, 64 B per sweep.  Per updated point: ax (a + b), wlo a + whi b,
//   az (a + b), factor rhs, 3 adds/subs: 11; keep x + wd s: 3; 14 flops per cell per sweep.
inline constexpr PerCell kSorSweep{64, 14};

// SmacSorPressure::increment's dp.fill(0) before the sweeps: writes dp, 8 B.
inline constexpr PerCell kFill{8, 0};

// FftPoisson::solve on NX x NY x NZ global cells (fft_poisson.cpp):
//   bytes: passes over the field, one read and one write of 8 B per cell each (the half
//   spectrum of NX/2 + 1 complex values taken as NX doubles): forward copy in 1, three
//   transposes (pack, unpack) 6, r2c along x 1, c2c along z 1 = 9; Thomas 1; backward 9
//   (the same, copy out last): 19 passes x 16 B = 304 B (MPI's own copies not counted).
//   flops: the usual FFT counts, 2.5 N log2 N for a real transform of N points and
//   5 N log2 N for a complex one: forward and backward x (2 x 2.5 log2 NX per cell) and z
//   (2 x 5 log2 NZ per complex point, (NX/2 + 1)/NX of them per cell); Thomas per complex
//   unknown: forward row (bj 2, m 2, cp 1, dp = (r scale - a dp)/m 8) 13, back 4: 17.
inline PerCell fft_solve_cost(int NX, int NZ) {
  const double half = (NX / 2 + 1) / static_cast<double>(NX);
  return {304, 2 * 2.5 * std::log2(NX) + half * (2 * 5 * std::log2(NZ) + 17)};
}

// CrankNicolsonStress::iterate with nc sweeps (crank_nicolson.cpp), halos apart:
//   before: 3 copies of v* (16 B each: 48 B), add_stretching(-dt) (kStretching);
//   per sweep: add_stretching, compute_stress_owned (kStress), stress divergence difference;
//   the last sweep copies v* (48 B); after: the change max over 6 arrays (48 B, 3 subs).
inline constexpr PerCell crank_nicolson_cost(int nc) {
  return PerCell{48 + 48 + 48, 3} + kStretching + nc * (kStretching + kStress + kStressDivergenceDifference);
}

}  // namespace efsi::bench
