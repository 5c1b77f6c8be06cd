// The time integrators (integrator.hpp) on the whole step: a profile of phi carried by a
// uniform flow, u = 1 along x, with no viscosity and no solid stress (mu = G = 0), so that
// the exact space-discrete solution is the WENO5 transport of phi alone.
//   - SSP-RK3 converges at third order in time against a run of the same grid at a much
//     smaller step, Euler at first order;
//   - on a front two cells wide, Euler's WENO5 transport grows oscillations (forward Euler is
//     unstable for an advection operator whose eigenvalues lie near the imaginary axis),
//     while SSP-RK3 keeps phi within its initial bounds;
//   - the table: euler is one stage (0, 1); an unknown name is a one-line ConfigError.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "mpi_test_support.hpp"
#include "solver_fixtures.hpp"

using namespace efsi;
using namespace efsi::testing;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr long kFrontSteps = 4000;

// nx x 4 x 4 cells on [0, 1] x [0, 4/nx] x [0, 4/nx]; phi(x) from `profile`, u = 1.
struct Carried {
  Channel c;
  Carried(int nx, double dt, const std::string& integrator, const std::function<double(double)>& profile) {
    const double h = 1.0 / nx;
    const Domain dom{{nx, 4, 4}, {1.0, 4 * h, 4 * h}};
    SolverConfig cfg;
    cfg.physics.mu = 0.0;
    cfg.physics.G = 0.0;
    cfg.physics.force = 0.0;
    cfg.dt = dt;
    cfg.integrator = integrator;
    cfg.velocity_limit = 10.0;
    c = make_channel(MPI_COMM_WORLD, dom, {0, 1, 1}, cfg, 0);
    FsiState& s = c.solver->state();
    Field& phi = s.phi();
    const Int3 n = phi.n();
    for (int k = 0; k < n[Z]; ++k)
      for (int j = 0; j < n[Y]; ++j)
        for (int i = 0; i < n[X]; ++i) phi(i, j, k) = profile(phi.coord(X, i) * h);
    c.solver->start_from_rest();  // Bt = sqrt(phi) I, ghosts filled
    s.vel(X).fill(1.0);
  }
  // phi's owned values along x (j = k = 0), gathered on every rank.
  std::vector<double> run(long steps) {
    for (long s = 0; s < steps; ++s) c.solver->step();
    c.solver->complete_exchange();
    const Field& phi = c.solver->state().phi();
    const int nx = c.decomp->global()[X];
    std::vector<double> local(nx, 0.0), global(nx, 0.0);
    for (int i = 0; i < phi.n()[X]; ++i) local[phi.offset()[X] + i] = phi(i, 0, 0);
    MPI_Allreduce(local.data(), global.data(), nx, MPI_DOUBLE, MPI_SUM, c.decomp->comm());
    return global;
  }
};

double max_difference(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::fabs(a[i] - b[i]));
  return d;
}

// Errors at t = 0.25 of steps dt0, dt0/2, dt0/4 against dt0/32 with rk3.
std::vector<double> temporal_errors(const std::string& integrator) {
  const int nx = 32;
  const double dt0 = 0.2 / nx, t = 0.25;
  auto smooth = [](double x) { return 0.5 + 0.25 * std::sin(2 * kPi * x); };
  const std::vector<double> ref = Carried(nx, dt0 / 32, "rk3", smooth).run(std::lround(t / (dt0 / 32)));
  std::vector<double> err;
  for (int r : {1, 2, 4}) {
    const double dt = dt0 / r;
    err.push_back(max_difference(Carried(nx, dt, integrator, smooth).run(std::lround(t / dt)), ref));
  }
  return err;
}

}  // namespace

// The observed orders between successive halvings of the step lie in [lo, hi].
void expect_order(const std::string& integrator, double lo, double hi) {
  const std::vector<double> e = temporal_errors(integrator);
  for (std::size_t i = 1; i < e.size(); ++i) {
    const double order = std::log2(e[i - 1] / e[i]);
    if (world_rank() == 0)
      std::printf("  %s: error %.3e -> %.3e, order %.2f\n", integrator.c_str(), e[i - 1], e[i], order);
    EXPECT_GT(order, lo);
    EXPECT_LT(order, hi);
  }
}

TEST(Integrators, Rk3IsThirdOrderInTimeOnSmoothTransport) { expect_order("rk3", 2.7, 3.4); }

TEST(Integrators, EulerIsFirstOrderInTimeOnSmoothTransport) { expect_order("euler", 0.85, 1.2); }

// A box of phi = 1 between two fronts about two cells wide, carried for kFrontSteps steps
// at a Courant number of 0.4: Euler's overshoot grows past 0.1, SSP-RK3's stays below 1e-3.
TEST(Integrators, Rk3StaysBoundedOnAFrontWhereEulerGrows) {
  const int nx = 64;
  const double dt = 0.4 / nx;
  const long steps = kFrontSteps;
  auto front = [](double x) { return 0.5 * (std::tanh((x - 0.25) * 64.0) - std::tanh((x - 0.75) * 64.0)); };
  auto excursion = [](const std::vector<double>& phi) {
    double e = 0;
    for (double v : phi) e = std::max({e, v - 1.0, -v});
    return e;
  };
  const double euler = excursion(Carried(nx, dt, "euler", front).run(steps));
  const double rk3 = excursion(Carried(nx, dt, "rk3", front).run(steps));
  if (world_rank() == 0) std::printf("  after %ld steps: phi outside [0, 1] by %.3e (euler), %.3e (rk3)\n", steps, euler, rk3);
  EXPECT_GT(euler, 0.1);
  EXPECT_LT(rk3, 1e-3);
}

TEST(Integrators, TableAndNames) {
  const Integrator& e = find_integrator("euler");
  ASSERT_EQ(e.stages.size(), 1u);
  EXPECT_EQ(e.stages[0].alpha, 0.0);
  EXPECT_EQ(e.stages[0].beta, 1.0);
  const Integrator& r = find_integrator("rk3");
  ASSERT_EQ(r.stages.size(), 3u);
  for (const IntegratorStage& s : r.stages) EXPECT_DOUBLE_EQ(s.alpha + s.beta, 1.0);  // convex
  const std::string msg = config_error_of([] { find_integrator("rk4"); });
  EXPECT_NE(msg.find("'rk4'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("euler, rk3"), std::string::npos) << msg;
}
