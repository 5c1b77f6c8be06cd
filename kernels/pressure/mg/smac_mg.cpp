#include "smac_mg.hpp"

namespace efsi {

void SmacMgPressure::attach(const CartDecomposition& decomp, const Domain& domain, FsiWork& work,
                            RegionTimers& timers) {
  mg_ = std::make_unique<MgPoisson>(decomp, domain, &timers);
  report_.setup_seconds = mg_->setup_seconds();
  // grad dp on the owned faces reads the low face ghosts.
  dp_halo_ = std::make_unique<HaloExchange>(decomp, std::vector<Field*>{&work.dp}, Reach::faces, &timers);
}

void SmacMgPressure::increment(PressureInputs& in) {
  const MgResult r = mg_->solve(in.work.div, in.work.dp, 1.0 / in.dt, stop_);
  report_.sweeps = r.cycles;
  report_.residual = r.residual;
  dp_halo_->exchange();
}

}  // namespace efsi
