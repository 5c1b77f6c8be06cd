// Explicit time-step limits: the paper's experiments (docs/numerics.md, "Experiments") pass, a dt ten times
// over each limit is refused with a message naming that limit, and the limits have the values
// of their formulas.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "config_error.hpp"
#include "time_step_limits.hpp"

using namespace efsi;

namespace {

constexpr double kRho = 1.0, kMu = 1.0, kG = 50.0;

Domain box(int nx, int ny, int nz, double lx, double ly, double lz) { return Domain{{nx, ny, nz}, {lx, ly, lz}}; }

const Domain kAccuracy = box(128, 128, 128, 7.2, 7.2, 7.2);
const Domain kWeak = box(64, 64, 64, 3.6, 3.6, 3.6);
const Domain kStrong = box(2048, 1024, 1024, 115.2, 57.6, 57.6);

std::string message_of(double dt, const Domain& d, double rho, double mu, double G, double u) {
  try {
    check_time_step(dt, d, rho, mu, G, u);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

void report(const char* name, double dt, const Domain& d, double u) {
  const TimeStepLimits l = time_step_limits(d, kRho, kMu, kG, u);
  std::printf("[ dt-limit ] %-34s dt=%-8g U=%-9.4g dt/viscous %.3g  dt/elastic %.3g  dt/advective %.3g\n", name, dt,
              u, dt / l.viscous, dt / l.elastic, dt / l.advective);
}

}  // namespace

TEST(TimeStepLimits, FormulasForThePaperSpacing) {
  const double h = 7.2 / 128;
  EXPECT_DOUBLE_EQ(h, 0.05625);
  EXPECT_DOUBLE_EQ(kWeak.spacing(X), h);
  EXPECT_DOUBLE_EQ(kStrong.spacing(Y), h);
  const double u = laminar_centreline_velocity(kAccuracy, kMu);
  EXPECT_DOUBLE_EQ(u, 7.2 * 7.2 / 8);  // 6.48
  const TimeStepLimits l = time_step_limits(kAccuracy, kRho, kMu, kG, u);
  EXPECT_DOUBLE_EQ(l.viscous, h * h / 6);  // 5.2734e-4
  EXPECT_NEAR(l.viscous, 5.2734375e-4, 1e-12);
  EXPECT_DOUBLE_EQ(l.elastic, 0.5 * kMu / kG);  // 0.01
  EXPECT_DOUBLE_EQ(l.advective, std::min(0.1 * h / u, 2 * kMu / (kRho * u * u)));
  EXPECT_DOUBLE_EQ(l.advective, 0.1 * h / u);  // 8.68e-4; 2 mu/(rho U^2) = 0.0476
  EXPECT_DOUBLE_EQ(l.smallest(), l.viscous);
  // Absent mechanisms impose nothing.
  const TimeStepLimits none = time_step_limits(kAccuracy, kRho, kMu, 0.0, 0.0);
  EXPECT_TRUE(std::isinf(none.elastic));
  EXPECT_TRUE(std::isinf(none.advective));
}

TEST(TimeStepLimits, PaperExperimentsPass) {
  // Accuracy (3.1): 40000 steps to t = 20, the flow develops: laminar centreline velocity.
  const double u_acc = laminar_centreline_velocity(kAccuracy, kMu);
  EXPECT_NO_THROW(check_time_step(5e-4, kAccuracy, kRho, kMu, kG, u_acc));
  EXPECT_DOUBLE_EQ(channel_velocity_estimate(kAccuracy, kRho, kMu, 20.0), u_acc);
  report("accuracy, ACM and FFT", 5e-4, kAccuracy, u_acc);

  // Weak scaling (3.2), one rank's block as the whole channel: even the developed flow passes.
  const double u_weak = laminar_centreline_velocity(kWeak, kMu);
  for (const double dt : {1.25e-5, 6.25e-5}) {
    EXPECT_NO_THROW(check_time_step(dt, kWeak, kRho, kMu, kG, u_weak)) << dt;
    report(dt < 3e-5 ? "weak, ACM, developed flow" : "weak, SOR, developed flow", dt, kWeak, u_weak);
  }

  // Strong scaling (3.3), full size, 50 ACM or 10 SOR steps from rest. Weak scaling on many
  // ranks in y builds the same tall channel; its equally short runs pass the same way.
  const struct {
    const char* name;
    double dt;
    int steps;
  } strong[] = {{"strong, ACM, 50 steps from rest", 1.25e-5, 50}, {"strong, SOR, 10 steps from rest", 6.25e-5, 10}};
  for (const auto& c : strong) {
    const double u = channel_velocity_estimate(kStrong, kRho, kMu, c.steps * c.dt);
    EXPECT_DOUBLE_EQ(u, c.steps * c.dt);
    EXPECT_NO_THROW(check_time_step(c.dt, kStrong, kRho, kMu, kG, u)) << c.name;
    report(c.name, c.dt, kStrong, u);
  }

  // The full-size strong channel run until its flow develops (U = 57.6^2/8 = 414.72, cell
  // Reynolds number 23) would break Euler's central-advection bound even at the ACM dt.
  const double u_dev = laminar_centreline_velocity(kStrong, kMu);
  report("strong, developed flow (refused)", 1.25e-5, kStrong, u_dev);
  const std::string m = message_of(1.25e-5, kStrong, kRho, kMu, kG, u_dev);
  EXPECT_NE(m.find("advective limit 2 mu/(rho U^2)"), std::string::npos) << m;
}

TEST(TimeStepLimits, TenTimesOverEachLimitIsRefusedByName) {
  const double h = 0.05625;
  {  // Viscous binds for the paper's parameters.
    const TimeStepLimits l = time_step_limits(kAccuracy, kRho, kMu, kG, 1.0);
    const std::string m = message_of(10 * l.viscous, kAccuracy, kRho, kMu, kG, 1.0);
    std::printf("[ dt-limit ] %s\n", m.c_str());
    EXPECT_NE(m.find("viscous"), std::string::npos) << m;
    EXPECT_NE(m.find("h^2 rho/(6 mu) = 5.273e-04"), std::string::npos) << m;
    EXPECT_NE(m.find("h=0.05625"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos);
  }
  {  // A stiff solid: mu/G far below the viscous limit.
    const double G = 1e5;
    const TimeStepLimits l = time_step_limits(kAccuracy, kRho, kMu, G, 1.0);
    ASSERT_LT(10 * l.elastic, l.viscous);
    const std::string m = message_of(10 * l.elastic, kAccuracy, kRho, kMu, G, 1.0);
    std::printf("[ dt-limit ] %s\n", m.c_str());
    EXPECT_NE(m.find("elastic"), std::string::npos) << m;
    EXPECT_NE(m.find("0.5 mu/G = 5.000e-06"), std::string::npos) << m;
  }
  {  // Fast flow, yet slow enough that the CFL part binds (0.1 h / U < 2 mu / (rho U^2) for
     // U < 20 mu / (rho h) = 356) and fast enough that 10x over it is under the viscous limit.
    const double u = 200.0;
    const TimeStepLimits l = time_step_limits(kAccuracy, kRho, kMu, kG, u);
    ASSERT_DOUBLE_EQ(l.advective, 0.1 * h / u);
    ASSERT_LT(10 * l.advective, std::min(l.viscous, l.elastic));
    const std::string m = message_of(10 * l.advective, kAccuracy, kRho, kMu, kG, u);
    std::printf("[ dt-limit ] %s\n", m.c_str());
    EXPECT_NE(m.find("advective limit 0.1 h/U"), std::string::npos) << m;
  }
  {  // Faster still, or less viscous: the cell-Reynolds bound of central advection binds.
    const double u = 1000.0;
    const TimeStepLimits l = time_step_limits(kAccuracy, kRho, kMu, kG, u);
    ASSERT_DOUBLE_EQ(l.advective, 2 * kMu / (kRho * u * u));
    const std::string m = message_of(10 * l.advective, kAccuracy, kRho, kMu, kG, u);
    std::printf("[ dt-limit ] %s\n", m.c_str());
    EXPECT_NE(m.find("advective limit 2 mu/(rho U^2)"), std::string::npos) << m;
  }
  // Just under and just over the tightest limit.
  const TimeStepLimits l = time_step_limits(kAccuracy, kRho, kMu, kG, 6.48);
  EXPECT_NO_THROW(check_time_step(l.smallest(), kAccuracy, kRho, kMu, kG, 6.48));
  EXPECT_THROW(check_time_step(l.smallest() * (1 + 1e-12), kAccuracy, kRho, kMu, kG, 6.48), ConfigError);
}

TEST(TimeStepLimits, NonCubicCellsUseTheFullViscousBound) {
  const Domain d = box(64, 32, 64, 3.6, 3.6, 3.6);  // dy = 2 dx
  const double dx = 0.05625, dy = 0.1125;
  const TimeStepLimits l = time_step_limits(d, kRho, kMu, 0.0, 0.0);
  EXPECT_DOUBLE_EQ(l.viscous, 1.0 / (2.0 * (2.0 / (dx * dx) + 1.0 / (dy * dy))));
  const std::string m = message_of(1.0, d, kRho, kMu, 0.0, 0.0);
  EXPECT_NE(m.find("viscous limit rho/(2 mu (1/dx^2+1/dy^2+1/dz^2))"), std::string::npos) << m;
}

TEST(TimeStepLimits, NonPhysicalInputIsRefused) {
  EXPECT_THROW(check_time_step(0.0, kWeak, kRho, kMu, kG, 1.0), ConfigError);
  EXPECT_THROW(check_time_step(-1e-5, kWeak, kRho, kMu, kG, 1.0), ConfigError);
  EXPECT_THROW(check_time_step(1e-5, kWeak, 0.0, kMu, kG, 1.0), ConfigError);
  EXPECT_THROW(check_time_step(1e-5, kWeak, kRho, 0.0, kG, 1.0), ConfigError);
  EXPECT_THROW(check_time_step(1e-5, kWeak, kRho, kMu, -1.0, 1.0), ConfigError);
  EXPECT_THROW(check_time_step(1e-5, kWeak, kRho, kMu, kG, -1.0), ConfigError);
  EXPECT_THROW(check_time_step(1e-5, box(0, 64, 64, 3.6, 3.6, 3.6), kRho, kMu, kG, 1.0), ConfigError);
  const std::string m = message_of(1e-5, kWeak, kRho, 0.0, kG, 1.0);
  EXPECT_NE(m.find("mu=0"), std::string::npos) << m;
}

// The Crank-Nicolson fixed point: h^2 rho / (24 mu) on cubic cells, named when exceeded.
TEST(TimeStepLimits, CrankNicolsonFixedPointLimit) {
  const efsi::Domain d{{32, 32, 32}, {3.6, 3.6, 3.6}};
  const double h = 3.6 / 32;
  EXPECT_NEAR(efsi::crank_nicolson_limit(d, 1.0, 1.0), h * h / 24, 1e-15);
  EXPECT_NEAR(efsi::crank_nicolson_limit(d, 2.0, 0.5), 4 * h * h / 24, 1e-15);
  EXPECT_NO_THROW(efsi::check_crank_nicolson_step(h * h / 24, d, 1.0, 1.0));
  try {
    efsi::check_crank_nicolson_step(1e-3, d, 1.0, 1.0);
    FAIL() << "dt = 1e-3 is above h^2/24 = 5.27e-4";
  } catch (const efsi::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("Crank-Nicolson"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("5.273e-04"), std::string::npos) << e.what();
  }
}
