#pragma once
// What a tendency kernel writes at each point of the field q it advances: the rate dq/dt
// itself, or the explicit Euler update q + dt dq/dt that every integrator stage takes
// (integrator.hpp).  The update is formed in the kernel's last pass over a line, where q
// is in cache as the centre of its own stencil: as a pass of its own it read the rate and
// q back from memory and wrote the result, 24 bytes a point for each of the ten advanced
// fields.  The sum is the one that pass formed, bit for bit.
#include "field.hpp"

namespace efsi {

struct RateOutput {
  bool euler = false;  // false: the rate
  double dt = 0.0;
  static RateOutput euler_update(double dt) { return {true, dt}; }
};

// The two stores as types, so that each kernel loop is compiled once per kind with no test
// inside it.
struct StoreRate {
  double operator()(const Field&, int, int, int, double r) const { return r; }
};
struct StoreEuler {
  double dt;
  double operator()(const Field& q, int i, int j, int k, double r) const { return q(i, j, k) + dt * r; }
};

// f(store) with the store `out` asks for.
template <class F>
void with_store(const RateOutput& out, F&& f) {
  if (out.euler) f(StoreEuler{out.dt});
  else f(StoreRate{});
}

}  // namespace efsi
