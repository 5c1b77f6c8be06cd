#include "smac_sor.hpp"

#include <string>

#include "compute_model.hpp"
#include "config_error.hpp"
#include "sor_work.hpp"

namespace efsi {

void check_sor_sweeps(double sweeps, const std::string& what) {
  if (!(sweeps >= 1)) throw ConfigError(what + " " + format_value(sweeps) + " must be at least 1");
}

SmacSorPressure::SmacSorPressure(CommMode comm, int sweeps, double omega, int sweeps_per_exchange,
                                 HaloPattern halo)
    : comm_(comm), sweeps_(sweeps), omega_(omega), sweeps_per_exchange_(sweeps_per_exchange), halo_(halo) {
  check_sor_sweeps(sweeps, "SOR sweeps per step N_S");
  report_.sweeps = sweeps;
}

void SmacSorPressure::attach(const CartDecomposition& decomp, const Domain& domain, FsiWork& work,
                             RegionTimers& timers) {
  sor_ = std::make_unique<SorPoisson>(decomp, domain, work.dp, comm_, &timers, omega_, sweeps_per_exchange_, halo_);
}

void SmacSorPressure::increment(PressureInputs& in) {
  {
    RegionTimers::Scope t(&in.timers, kSorSweepsRegion);
    compute_stage(kFill, double(product(in.work.dp.n())), [&] { in.work.dp.fill(0.0); });
  }
  // The sweeps leave dp's ghosts current, the low face ghosts included.
  sor_->sweeps(in.work.div, sweeps_, 1.0 / in.dt);
}

}  // namespace efsi
