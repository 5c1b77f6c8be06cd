#include "time_step_limits.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "config_error.hpp"

namespace efsi {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string fmt(const char* format, double a) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, a);
  return buf;
}

std::string g(double a) { return fmt("%.6g", a); }
std::string e(double a) { return fmt("%.3e", a); }

void require(bool ok, const std::string& what) {
  if (!ok) throw ConfigError(what);
}

void validate(const Domain& d, double rho, double mu, double G, double u_estimate) {
  for (int a = 0; a < 3; ++a)
    require(d.cells[a] > 0 && d.length[a] > 0.0 && std::isfinite(d.length[a]),
            "time-step check: the domain needs positive cells and lengths, got cells " + to_string(d.cells) +
                " and length " + g(d.length[a]) + " on axis " + std::to_string(a));
  require(rho > 0.0 && std::isfinite(rho), "time-step check: rho=" + g(rho) + " must be positive");
  require(mu > 0.0 && std::isfinite(mu),
          "time-step check: mu=" + g(mu) + " must be positive (explicit Euler needs viscosity to stay stable)");
  require(G >= 0.0 && std::isfinite(G), "time-step check: G=" + g(G) + " must be zero or positive");
  require(u_estimate >= 0.0 && std::isfinite(u_estimate),
          "time-step check: velocity estimate " + g(u_estimate) + " must be zero or positive");
}

double min_spacing(const Domain& d) { return std::min({d.spacing(X), d.spacing(Y), d.spacing(Z)}); }

bool cubic(const Domain& d) { return d.spacing(X) == d.spacing(Y) && d.spacing(Y) == d.spacing(Z); }

double viscous_limit(const Domain& d, double rho, double mu) {
  double sum = 0.0;
  for (int a = 0; a < 3; ++a) sum += 1.0 / (d.spacing(a) * d.spacing(a));
  return rho / (2.0 * mu * sum);
}

double elastic_limit(double mu, double G) { return G > 0.0 ? kElasticSafety * mu / G : kInf; }

double cfl_limit(const Domain& d, double u) { return u > 0.0 ? kAdvectiveCfl * min_spacing(d) / u : kInf; }

double cell_reynolds_limit(double rho, double mu, double u) { return u > 0.0 ? 2.0 * mu / (rho * u * u) : kInf; }

}  // namespace

double TimeStepLimits::smallest() const { return std::min({viscous, elastic, advective}); }

TimeStepLimits time_step_limits(const Domain& domain, double rho, double mu, double G, double u_estimate) {
  validate(domain, rho, mu, G, u_estimate);
  return {viscous_limit(domain, rho, mu), elastic_limit(mu, G),
          std::min(cfl_limit(domain, u_estimate), cell_reynolds_limit(rho, mu, u_estimate))};
}

void check_time_step(double dt, const Domain& domain, double rho, double mu, double G, double u_estimate) {
  require(dt > 0.0 && std::isfinite(dt), "dt=" + g(dt) + " must be positive");
  const TimeStepLimits lim = time_step_limits(domain, rho, mu, G, u_estimate);
  if (dt <= lim.smallest()) return;

  // Name the tightest limit: meeting it meets the others.
  const std::string head = "dt=" + g(dt) + " exceeds the ";
  const double h = min_spacing(domain);
  if (lim.viscous <= lim.elastic && lim.viscous <= lim.advective) {
    if (cubic(domain))
      throw ConfigError(head + "viscous limit h^2 rho/(6 mu) = " + e(lim.viscous) + " (h=" + g(h) +
                        ", rho=" + g(rho) + ", mu=" + g(mu) + ")");
    throw ConfigError(head + "viscous limit rho/(2 mu (1/dx^2+1/dy^2+1/dz^2)) = " + e(lim.viscous) +
                      " (dx=" + g(domain.spacing(X)) + ", dy=" + g(domain.spacing(Y)) + ", dz=" +
                      g(domain.spacing(Z)) + ", rho=" + g(rho) + ", mu=" + g(mu) + ")");
  }
  if (lim.elastic <= lim.advective)
    throw ConfigError(head + "elastic limit " + g(kElasticSafety) + " mu/G = " + e(lim.elastic) + " (mu=" +
                      g(mu) + ", G=" + g(G) + ")");
  if (cfl_limit(domain, u_estimate) <= cell_reynolds_limit(rho, mu, u_estimate))
    throw ConfigError(head + "advective limit " + g(kAdvectiveCfl) + " h/U = " + e(lim.advective) + " (h=" +
                      g(h) + ", U=" + g(u_estimate) + ")");
  throw ConfigError(head + "advective limit 2 mu/(rho U^2) = " + e(lim.advective) + " (U=" + g(u_estimate) +
                    ", rho=" + g(rho) + ", mu=" + g(mu) + ")");
}

double crank_nicolson_limit(const Domain& domain, double rho, double mu) {
  double sum = 0.0;
  for (int a = 0; a < 3; ++a) sum += 1.0 / (domain.spacing(a) * domain.spacing(a));
  return rho / (8.0 * mu * sum);
}

void check_crank_nicolson_step(double dt, const Domain& domain, double rho, double mu) {
  const double lim = crank_nicolson_limit(domain, rho, mu);
  if (dt <= lim) return;
  throw ConfigError("dt=" + g(dt) + " exceeds the Crank-Nicolson fixed-point limit rho/(8 mu (1/dx^2+1/dy^2+1/dz^2)) = " +
                    e(lim) + " (h=" + g(min_spacing(domain)) + ", rho=" + g(rho) + ", mu=" + g(mu) +
                    "): each of the N_C sweeps must at least halve the iterate's error; use a smaller --dt or --nc 0");
}

double laminar_centreline_velocity(const Domain& domain, double mu, double f) {
  const double ly = domain.length[Y];
  return f * ly * ly / (8.0 * mu);
}

double channel_velocity_estimate(const Domain& domain, double rho, double mu, double t_end, double f) {
  return std::min(laminar_centreline_velocity(domain, mu, f), f * t_end / rho);
}

}  // namespace efsi
