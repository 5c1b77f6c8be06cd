#pragma once
// Time integrators as tables of coefficients (docs/numerics.md, "time integration").
//
// A step of S stages: stage s takes one forward-Euler sub-step E of the whole projection
// method (stress, momentum, transport, pressure increment, projection) from u^(s) and
// blends it with the step's start,
//   u^(0) = u^n,   u^(s+1) = alpha_s u^n + beta_s E(u^(s)),   u^{n+1} = u^(S),
// for every state field (velocity, pressure, phi, Bt).  This is Shu and Osher's form: each
// stage is a convex combination of Euler sub-steps, so whatever bounds one Euler sub-step
// (the non-oscillatory WENO5 transport at a small enough time step) bounds the whole
// step, and a blend of divergence-free velocities stays divergence-free.  A new integrator
// is one more row of kIntegrators.  The sub-step's updates q + dt dq/dt are written by the
// momentum and transport kernels themselves (physics/rate_output.hpp).
#include <string>
#include <vector>

#include "field.hpp"
#include "grid_types.hpp"

namespace efsi {

struct IntegratorStage {
  double alpha;  // weight of u^n
  double beta;   // weight of the Euler sub-step
};

struct Integrator {
  std::string name;
  std::string description;
  std::vector<IntegratorStage> stages;
  int order;  // in time, on smooth solutions
};

// euler: one stage (0, 1), first order, the paper's and the default;
// rk3:   SSP-RK3 (Shu and Osher 1988), third order.
const std::vector<Integrator>& integrators();

// Throws ConfigError naming `name` and the integrators there are.
const Integrator& find_integrator(const std::string& name);

// The stage's blend: q = alpha q0 + beta q on every owned point of q (the owned top wall
// face included).  (0, 1) leaves q untouched.
void blend(Field& q, const Field& q0, const IntegratorStage& stage);

}  // namespace efsi
