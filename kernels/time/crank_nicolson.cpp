#include "crank_nicolson.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "compute_model.hpp"
#include "config_error.hpp"
#include "kernel_costs.hpp"

namespace efsi {

namespace {

std::array<Field, 6> tensor_fields(const CartDecomposition& decomp, const std::array<Field, 6>& like,
                                   const char* suffix) {
  auto make = [&](int c) {
    FieldSpec spec = like[c].spec();
    spec.name += suffix;
    return Field(decomp, spec);
  };
  return {make(0), make(1), make(2), make(3), make(4), make(5)};
}

int checked_sweeps(int sweeps) {
  if (sweeps < 1)
    throw ConfigError("Crank-Nicolson sweeps per step N_C=" + std::to_string(sweeps) + " must be at least 1");
  return sweeps;
}

}  // namespace

CrankNicolsonStress::CrankNicolsonStress(const CartDecomposition& decomp, FsiWork& work, int sweeps,
                                         RegionTimers* timers, Reach v_reach)
    : sweeps_(checked_sweeps(sweeps)),
      timers_(timers),
      v_explicit_{Field(decomp, work.vstar[0].spec()), Field(decomp, work.vstar[1].spec()),
                  Field(decomp, work.vstar[2].spec())},
      v_previous_{Field(decomp, work.vstar[0].spec()), Field(decomp, work.vstar[1].spec()),
                  Field(decomp, work.vstar[2].spec())},
      b_advected_(tensor_fields(decomp, work.B_new, "_adv")),
      tau_star_(tensor_fields(decomp, work.tau, "*")),
      v_halo_(decomp, {&work.vstar[0], &work.vstar[1], &work.vstar[2]}, v_reach, timers),
      tau_halo_(decomp,
                {&tau_star_[0], &tau_star_[1], &tau_star_[2], &tau_star_[3], &tau_star_[4], &tau_star_[5]},
                Reach::faces, timers) {}

void CrankNicolsonStress::iterate(const FsiState& state, FsiWork& w, const Physics& ph, double dt) {
  const FieldSet s = state.fields();
  const double c = 0.5 * dt / ph.rho;
  const Int3 n = s.decomp().local();
  const Box owned{{0, 0, 0}, n};
  const Box faces = full_boxes(n).momentum;
  // The simulation build charges the counted work of each piece (kernel_costs.hpp,
  // crank_nicolson_cost) instead of running it (compute_model.hpp).
  const double cells = double(product(n));
  {
    RegionTimers::Scope t(timers_, Region::compute);
    compute_stage(kStretching + kAddStressDivergence, cells, [&] {
      // Bt^N - dt v^N.grad Bt^N: the explicit transport less its stretching.
      add_stretching(s, -dt, w.B_new, b_advected_, owned);
      // v* - c div tau^N: the part of every sweep's update that does not change.
      add_stress_divergence(s, w.tau, -c, w.vstar, v_explicit_, faces);
    });
  }
  for (int m = 0; m < sweeps_; ++m) {
    v_halo_.exchange();
    {
      RegionTimers::Scope t(timers_, Region::compute);
      // tau* from v* and Bt* (Bt^N stretched by the iterate's gradient), with phi^N.
      compute_stage(kStretchedStress, cells, [&] {
        stretched_stress_owned(s.with_velocity(w.vstar), ph, dt, b_advected_, w.root_phi, tau_star_);
      });
    }
    tau_halo_.exchange();
    RegionTimers::Scope t(timers_, Region::compute);
    const bool last = m + 1 == sweeps_;
    compute_stage(last ? kAddStressDivergence + kCopyVelocity : kAddStressDivergence, cells, [&] {
      if (last)  // keep the last iterate to measure the final sweep's change
        for (int a = 0; a < 3; ++a) v_previous_[a].copy_from(w.vstar[a]);
      add_stress_divergence(s, tau_star_, c, v_explicit_, w.vstar, faces);
    });
  }
  {
    RegionTimers::Scope t(timers_, Region::compute);
    double result = 0.0;  // the lambda reduces its own local (see acm_moments)
    compute_stage(kVelocityChange, cells, [&] {
      double change = 0.0;
      for (int a = 0; a < 3; ++a) {
        const Field &now = w.vstar[a], &before = v_previous_[a];
#pragma omp parallel for collapse(2) schedule(static) reduction(max : change)
        for (int k = 0; k < n[Z]; ++k)
          for (int j = 0; j < n[Y]; ++j)
            for (int i = 0; i < n[X]; ++i) change = std::max(change, std::fabs(now(i, j, k) - before(i, j, k)));
      }
      result = change;
    });
    last_change_ = result;
  }
  v_halo_.exchange();
}

}  // namespace efsi
