// Layered Poiseuille flow (docs/numerics.md, "Validation cases"): a solid slab a < y < h - a between fluid
// layers, driven by f, settles to a rigid plug that carries the shear stress elastically:
// Bt12 = -f (y - h/2) / G, Bt11 = 1 + Bt12^2, Bt22 = Bt33 = 1 inside the slab, Poiseuille
// flow in the fluid. Exercises the solid stress, the upper-convected terms and the slab
// set-up of the channel case.
#include <gtest/gtest.h>
#include <mpi.h>

#include <cmath>

#include "channel_case.hpp"
#include "solver_fixtures.hpp"

using namespace efsi;

namespace {

// h = 1 with 16 cells: the slab edge a = 0.25 falls on a cell face, so phi is exactly 0
// or 1 and the interface is one edge plane. G = 4 keeps the elastic relaxation time
// mu/G short enough to reach the steady state by t = 5 (measured: Bt12 within 2e-5 of its
// limit), while the strain Bt12 = 0.0625 at the slab edge leaves Bt11 - 1 measurable.
constexpr int kNy = 16;
constexpr double kH = 1.0, kA = 0.25, kG = 4.0, kF = 1.0, kMu = 1.0;

}  // namespace

TEST(LayeredPoiseuille, SettlesToThePlugWithElasticShear) {
  ChannelCase c;
  const double dy = kH / kNy;
  c.domain = Domain{{6, kNy, 6}, {6 * dy, kH, 6 * dy}};
  c.slab = kA;
  c.solver.physics.G = kG;
  c.solver.dt = 5e-4;
  const double t_end = 5.0;
  int ranks = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &ranks);
  validate_case(c, ranks, t_end);
  CartDecomposition dec(MPI_COMM_WORLD, c.domain.cells, kTransportHalo, {0, 0, 0});
  auto solver = build_solver(c, dec, {});
  const int first_solid = int(std::lround(kA / dy)), last_solid = kNy - first_solid - 1;
  {
    const auto phi0 = efsi::testing::xz_mean_profile(solver->state().phi(), c.domain, dec.comm());
    ASSERT_EQ(phi0[first_solid], 1.0);
    ASSERT_EQ(phi0[first_solid - 1], 0.0);
    ASSERT_EQ(phi0[last_solid], 1.0);
    ASSERT_EQ(phi0[last_solid + 1], 0.0);
  }
  const long steps = std::lround(t_end / c.solver.dt);
  for (long s = 0; s < steps; ++s) solver->step();
  solver->complete_exchange();

  const FsiState& st = solver->state();
  using efsi::testing::xz_mean_profile;
  const auto u = xz_mean_profile(st.vel(X), c.domain, dec.comm());
  const auto b11 = xz_mean_profile(st.B(0, 0), c.domain, dec.comm());
  const auto b22 = xz_mean_profile(st.B(1, 1), c.domain, dec.comm());
  const auto b33 = xz_mean_profile(st.B(2, 2), c.domain, dec.comm());
  const auto b12 = xz_mean_profile(st.B(0, 1), c.domain, dec.comm());  // at y = j dy (edges)


  // Inside the slab, two cells clear of the interface: exact elastic shear.
  const double edge_strain = kF * (kH / 2 - kA) / kG;  // Bt12 at the slab edge, 0.0625
  for (int j = first_solid + 2; j <= last_solid - 1; ++j) {
    const double y = j * dy;  // Bt12 sits on the y faces
    EXPECT_NEAR(b12[j], -kF * (y - kH / 2) / kG, 1e-3 * edge_strain) << "Bt12 at y=" << y;
  }
  for (int j = first_solid + 2; j <= last_solid - 2; ++j) {
    const double b12c = 0.5 * (b12[j] + b12[j + 1]);  // at the cell centre
    EXPECT_NEAR(b11[j], 1.0 + b12c * b12c, 1e-3 * edge_strain * edge_strain) << "Bt11 at j=" << j;
    // Bt22 - 1 = 2 int dv/dy dt: only the ACM's small divergence moves it (measured 8e-7).
    EXPECT_NEAR(b22[j], 1.0, 1e-5) << "Bt22 at j=" << j;
    EXPECT_NEAR(b33[j], 1.0, 1e-5) << "Bt33 at j=" << j;
  }

  // A rigid plug: uniform velocity across the slab (to the 1e-5 of the remaining transient).
  double umin = 1e300, umax = -1e300;
  for (int j = first_solid; j <= last_solid; ++j) umin = std::min(umin, u[j]), umax = std::max(umax, u[j]);
  EXPECT_LT(umax - umin, 1e-4 * umax);
  // Its speed: exact f a (h - a) / (2 mu). The interface edge stops shearing too (Bt22 > 0
  // there), so the plug takes the speed of the last fluid cell: the error is one cell of
  // shear at the interface, f (h/2 - a) dy / mu (first order in dy).
  const double plug = kF * kA * (kH - kA) / (2 * kMu);
  EXPECT_NEAR(umax, plug, kF * (kH / 2 - kA) * dy / kMu);

  // Fluid layers away from the interface: Poiseuille to the wall ghost's second-order error.
  for (int j = 0; j < first_solid - 1; ++j) {
    const double y = (j + 0.5) * dy;
    EXPECT_NEAR(u[j], kF / (2 * kMu) * y * (kH - y), kF * dy * dy / (4 * kMu)) << "u at y=" << y;
    EXPECT_NEAR(u[kNy - 1 - j], u[j], 1e-12) << "symmetry";
  }
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0)
    std::printf("  plug %.6f (exact %.6f), Bt12 at y=0.4375: %.7f (exact %.7f), Bt11-1-Bt12^2 at centre: %.2e\n", umax,
                plug, b12[7], -kF * (7 * dy - kH / 2) / kG, b11[7] - 1 - std::pow(0.5 * (b12[7] + b12[8]), 2));
}
