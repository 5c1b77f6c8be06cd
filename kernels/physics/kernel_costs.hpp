#pragma once
// Bytes and flops per owned cell of the kernels bench_kernels times, counted from the code,
// under the conventions of kernels/grid/work_count.hpp.  The pressure methods'
// own kernels are counted in their folders (acm_work.hpp, sor_work.hpp, fft_work.hpp).
#include <cmath>

#include "work_count.hpp"

namespace efsi {

// compute_stress (fsi_equations.cpp solid_root and stress_component, constitutive.hpp):
//   solid_root: reads phi, writes sqrt(max(phi, 0)) once per centre: 16 B, 1 flop (sqrt);
//   six components: read u, v, w, sqrt(phi), Bt11..Bt23 (10 arrays), write tau11..tau23 (6):
//   16 x 8 = 128 B.
//   diagonal tau_AA = 2mu dv_A/dx_A + G sqrt(phi)(Bt_AA - tr/3):
//     difference 2 (sub, mul); tr 2 adds, tr/3 1, Bt - 1, sqrt * 1; 2mu*, G*, + 3
//     = 2 + 5 + 3 = 10, three of them: 30
//   off-diagonal tau_AB = 2mu 0.5 (dv_A/dx_B + dv_B/dx_A) + G avg4(sqrt phi) Bt_AB:
//     strain 2 + 2 + add + 0.5* = 6; average of 4 sqrt(phi): 3 adds + 1 mul = 4, times Bt 1;
//     2mu*, G*, + 3: 6 + 5 + 3 = 14, three of them: 42
//   total 144 B, 73 flops.
inline constexpr PerCell kStress{144, 73};

// compute_vstar, the momentum right-hand side (vstar_component), three face components:
//   reads u, v, w, p, tau11..tau23 (10), writes u*, v*, w* (3): 13 x 8 = 104 B.
//   per component C: three skew-symmetric advection terms, each two flux velocities
//   (add, mul: 2 each) and 0.5 h^-1 (up uc - lo uc) (mul, 2 mul, sub, mul: 5) = 9, summed
//   (2 adds): 29; three stress-divergence terms (sub, mul: 2 each) summed: 8; grad p 2;
//   -adv + (div tau - grad p)/rho + f: 4; the Euler update v + dt dv/dt (rate_output.hpp;
//   v is read for the advection anyway) 2.  29 + 8 + 2 + 4 + 2 = 45, three: 135 flops.
inline constexpr PerCell kMomentum{104, 135};

// StressAndMomentum (fsi_equations.hpp), the two above fused plane by plane with tau kept
//   on a ring of planes in cache: solid_root 16 B; reads u, v, w, p, sqrt(phi), Bt11..Bt23
//   (11 arrays), writes u*, v*, w* (3): 14 x 8 = 112 B; with solid_root 128 B.  Flops as the
//   two kernels: 73 + 135 = 208 (the edge planes on each thread's first plane are formed
//   twice: 1 plane in n_z / threads, not counted).
inline constexpr PerCell kStressAndMomentum{128, 208};

// compute_transport, WENO5 advection of phi and the six Bt components with the
// upper-convected stretching of Bt (transport_component, weno5.hpp); a fused multiply-add
// (mul_add) counts 2 flops:
//   reads u, v, w, phi, Bt11..Bt23 (10), writes phi_new, Bt_new (7): 17 x 8 = 136 B.
//   weno5_upwind_side: 5 raw differences 5; weno5_upwind: candidates 5 + 4 + 4, indicators'
//   c 3 x 3 and l 4 + 1 + 4, s_k 5 each, squares 3, alpha 1 + 2 + 2, numerator 5,
//   denominator 2, division 1: 62; so 67.  One advection v_M dq/dx_M = average of v_M to q's
//   location (2 points: 2 flops, or 8 points: 8 for an edge component along its unstaggered
//   axis) + 67 + |v| h^-1/6 and its product (2): 71 or 77.
//   phi: 3 x 71 + 2 adds + the sign (1) = 216.
//   Bt_AB: 3 advections (213 for diagonal, 71 + 71 + 77 = 219 for edge components) + 2 adds;
//   stretching sum_M L_AM Bt_MB + Bt_AM L_BM, each factor averaged to Bt_AB's location
//   (grad_v_at: n raw differences averaged, then h^-1: 2, 5 or 9 flops for n = 1, 2, 4;
//   a Bt average of 4 points 4; the term mul and mul_add 3): 7 + 29 + 29 = 65 (diagonal)
//   or 18 + 18 + 29 = 65 (edge), + 2 adds; uc - adv 1.  Diagonal 213 + 2 + 65 + 2 + 1 = 283,
//   edge 289.  Each of the seven fields' Euler update q + dt rate (q is its own stencil's
//   centre) 2.
//   total 216 + 3 x 283 + 3 x 289 + 7 x 2 = 1946 flops.
inline constexpr PerCell kTransport{136, 1946};

// Of those, the weno5_advection calls (the raw differences 5, the scheme 62, |v| h^-1/6 and
// its product 2: 69 flops each), 3 for phi and for each of the six Bt components: the part
// measured against the WENO5 roof (compute_probe.hpp); the averages, stretching and updates
// are measured against the multiply-add peak.
inline constexpr double kWenoAdvectionFlops = 69;
inline constexpr double kTransportWenoFlops = 21 * kWenoAdvectionFlops;

// add_stretching (Crank-Nicolson, once per step): the stretching part of the above on base:
//   reads u, v, w, Bt (6), base (6), writes out (6): 21 x 8 = 168 B; per component
//   65 + 2 adds + base + dt uc (2) = 69, six: 414 flops.
inline constexpr PerCell kStretching{168, 414};

// stretched_stress_owned (each Crank-Nicolson sweep): add_stretching and the six stress
//   components fused, Bt* = base + dt uc kept in registers: reads u, v, w, Bt (6), base (6),
//   sqrt(phi), writes tau (6): 22 x 8 = 176 B; flops 414 + 72 (kStress less its sqrt pass),
//   and each of the three normal components forms all three diagonal Bt* (4 more each): 498.
inline constexpr PerCell kStretchedStress{176, 498};

// add_stress_divergence (Crank-Nicolson: once per step on the explicit stress, then each
//   sweep): reads tau (6), base (3), writes out (3): 12 x 8 = 96 B; per face component
//   3 x (sub, mul) + 2 adds, then base + c div as one mul_add (2): 10, three: 30.
inline constexpr PerCell kAddStressDivergence{96, 30};

// FsiSolver::compute_divergence: reads u*, v*, w*, writes div: 32 B; 3 x (sub, mul) + 2 = 8.
inline constexpr PerCell kDivergence{32, 8};

// FsiSolver::project: reads p, dp, u*, v*, w*, writes p, u, v, w: 72 B;
//   p += dp 1, each velocity u* - c (dp - dp_low) 3: 10 flops.
inline constexpr PerCell kProject{72, 10};

// The Crank-Nicolson iteration's last sweep keeps a copy of v* (reads 3, writes 3: 48 B),
// and the change of that sweep is a max over the 6 arrays (48 B, 3 subs).
inline constexpr PerCell kCopyVelocity{48, 0};
inline constexpr PerCell kVelocityChange{48, 3};

// CrankNicolsonStress::iterate with nc sweeps (crank_nicolson.cpp), halos apart:
//   before: add_stretching(-dt) (kStretching), v* - c div tau^N (kAddStressDivergence);
//   per sweep: stretched_stress_owned, v* = that base + c div tau* (kAddStressDivergence);
//   the last sweep copies v*; after: the change.
inline constexpr PerCell crank_nicolson_cost(int nc) {
  return kCopyVelocity + kVelocityChange + kStretching + kAddStressDivergence +
         nc * (kStretchedStress + kAddStressDivergence);
}

}  // namespace efsi
