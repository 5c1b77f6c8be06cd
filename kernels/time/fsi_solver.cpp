#include "fsi_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

namespace efsi {

FsiSolver::FsiSolver(const CartDecomposition& decomp, const Domain& domain, const SolverConfig& config,
                     std::unique_ptr<PressureMethod> pressure)
    : decomp_(decomp), config_(config), state_(decomp, domain), work_(decomp), pressure_(std::move(pressure)) {
  if (config_.divergence_limit <= 0.0)
    config_.divergence_limit =
        0.005 * config_.velocity_limit / std::min({domain.spacing(X), domain.spacing(Y), domain.spacing(Z)});
  state_halo_ = std::make_unique<HaloExchange>(decomp, state_.all(), Reach::full, &timers_);
  vstar_halo_ = std::make_unique<HaloExchange>(
      decomp, std::vector<Field*>{&work_.vstar[0], &work_.vstar[1], &work_.vstar[2]}, Reach::faces, &timers_);
  div_halo_ = std::make_unique<HaloExchange>(decomp, std::vector<Field*>{&work_.div}, Reach::faces, &timers_);
  if (config_.cn_sweeps > 0) cn_ = std::make_unique<CrankNicolsonStress>(decomp, work_, config_.cn_sweeps, &timers_);
  pressure_->attach(decomp, domain, work_, timers_);
}

void FsiSolver::start_from_rest() {
  complete_exchange();
  state_.set_unstrained_rest();
  state_halo_->exchange();
  steps_ = 0;
  time_ = 0.0;
}

void FsiSolver::impose_laminar_flow() {
  complete_exchange();
  Field& u = state_.vel(X);
  const Domain& d = state_.domain();
  const double dy = d.spacing(Y), ly = d.length[Y], c = config_.physics.force / (2.0 * config_.physics.mu);
  const Int3 n = u.n();
  for (int j = 0; j < n[Y]; ++j) {
    const double y = u.coord(Y, j) * dy;
    const double value = c * y * (ly - y);
    for (int k = 0; k < n[Z]; ++k)
      for (int i = 0; i < n[X]; ++i) u(i, j, k) = value;
  }
  state_halo_->exchange();
}

void FsiSolver::complete_exchange() {
  if (pending_) {
    state_halo_->finish();
    pending_ = false;
  }
}

void FsiSolver::step() {
  const Int3 n = decomp_.local();
  const KernelBoxes full = full_boxes(n);
  const double dt = config_.dt;
  const Physics& ph = config_.physics;

  if (config_.comm == CommMode::async && pending_) {
    // The last step's exchange is in flight: do everything that reads no ghost.
    const KernelBoxes in = interior_boxes(n);
    {
      RegionTimers::Scope t(&timers_, Region::compute);
      compute_stress(state_, ph, work_.tau, in.stress_centres, in.stress_edges);
      compute_vstar(state_, ph, work_.tau, dt, work_.vstar, in.momentum);
      compute_transport(state_, dt, work_.phi_new, work_.B_new, in.transport);
    }
    complete_exchange();
    {
      RegionTimers::Scope t(&timers_, Region::compute);
      for_each_shell_box(full.stress_centres, in.stress_centres,
                         [&](const Box& b) { compute_stress(state_, ph, work_.tau, b, Box{}); });
      for_each_shell_box(full.stress_edges, in.stress_edges,
                         [&](const Box& b) { compute_stress(state_, ph, work_.tau, Box{}, b); });
      for_each_shell_box(full.momentum, in.momentum,
                         [&](const Box& b) { compute_vstar(state_, ph, work_.tau, dt, work_.vstar, b); });
    }
    vstar_halo_->begin();
    {
      RegionTimers::Scope t(&timers_, Region::compute);
      for_each_shell_box(full.transport, in.transport,
                         [&](const Box& b) { compute_transport(state_, dt, work_.phi_new, work_.B_new, b); });
    }
    vstar_halo_->finish();
  } else {
    complete_exchange();
    {
      RegionTimers::Scope t(&timers_, Region::compute);
      compute_stress(state_, ph, work_.tau, full.stress_centres, full.stress_edges);
      compute_vstar(state_, ph, work_.tau, dt, work_.vstar, full.momentum);
    }
    if (config_.comm == CommMode::async) {
      vstar_halo_->begin();
      {
        RegionTimers::Scope t(&timers_, Region::compute);
        compute_transport(state_, dt, work_.phi_new, work_.B_new, full.transport);
      }
      vstar_halo_->finish();
    } else {
      RegionTimers::Scope t(&timers_, Region::compute);
      compute_transport(state_, dt, work_.phi_new, work_.B_new, full.transport);
    }
    if (config_.comm == CommMode::sync) vstar_halo_->exchange();
  }
  // Its sweeps exchange v* in all 26 directions, the last one included.
  if (cn_) cn_->iterate(state_, work_, ph, dt);

  const double divmax = compute_divergence();
  div_halo_->exchange();
  PressureInputs in{state_, work_, ph, dt, timers_};
  pressure_->increment(in);
  const double umax = project();

  std::swap(state_.phi(), work_.phi_new);
  for (int c = 0; c < 6; ++c) std::swap(state_.B(c), work_.B_new[c]);
  ++steps_;
  time_ += dt;
  if (config_.check_every > 0 && steps_ % config_.check_every == 0) check_blow_up(umax, divmax);

  if (config_.comm == CommMode::async) {
    state_halo_->begin();
    pending_ = true;
  } else {
    state_halo_->exchange();
  }
}

namespace {
// NaN compares false: make it infinite so that a max carries it.
double magnitude(double x) { return x == x ? std::fabs(x) : std::numeric_limits<double>::infinity(); }
}  // namespace

double FsiSolver::compute_divergence() {
  RegionTimers::Scope t(&timers_, Region::compute);
  const Int3 n = decomp_.local();
  const Domain& d = state_.domain();
  const double rho = config_.physics.rho;
  const double ix = rho / d.spacing(X), iy = rho / d.spacing(Y), iz = rho / d.spacing(Z);
  const Field &u = work_.vstar[0], &v = work_.vstar[1], &w = work_.vstar[2];
  Field& div = work_.div;
  double dmax = 0.0;
#pragma omp parallel for collapse(2) schedule(static) reduction(max : dmax)
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) {
        const double dv = (u(i + 1, j, k) - u(i, j, k)) * ix + (v(i, j + 1, k) - v(i, j, k)) * iy +
                         (w(i, j, k + 1) - w(i, j, k)) * iz;
        div(i, j, k) = dv;
        dmax = std::max(dmax, magnitude(dv));
      }
  return dmax;
}

double FsiSolver::project() {
  RegionTimers::Scope t(&timers_, Region::compute);
  const Int3 n = decomp_.local();
  const Domain& d = state_.domain();
  const double c = config_.dt / config_.physics.rho;
  const Field& dp = work_.dp;
  Field& p = state_.p();
  const int wall_lo = decomp_.wall_row_below();
  const double cx = c / d.spacing(X), cy = c / d.spacing(Y), cz = c / d.spacing(Z);
  double umax = 0.0;
#pragma omp parallel for collapse(2) schedule(static) reduction(max : umax)
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) {
        p(i, j, k) += dp(i, j, k);
        const double q = dp(i, j, k);
        const double u = work_.vstar[0](i, j, k) - cx * (q - dp(i - 1, j, k));
        const double v = j == wall_lo ? 0.0 : work_.vstar[1](i, j, k) - cy * (q - dp(i, j - 1, k));
        const double w = work_.vstar[2](i, j, k) - cz * (q - dp(i, j, k - 1));
        state_.vel(X)(i, j, k) = u;
        state_.vel(Y)(i, j, k) = v;
        state_.vel(Z)(i, j, k) = w;
        umax = std::max({umax, magnitude(u), magnitude(v), magnitude(w)});
      }
  return umax;
}

void FsiSolver::check_blow_up(double local_umax, double local_divmax) {
  const double local[2] = {local_umax, local_divmax};
  double global[2] = {0, 0};
  {
    RegionTimers::Scope t(&timers_, Region::reduce);
    MPI_Allreduce(local, global, 2, MPI_DOUBLE, MPI_MAX, decomp_.comm());
  }
  const bool velocity_bad = !(global[0] <= config_.velocity_limit);
  if (!velocity_bad && global[1] <= config_.divergence_limit) return;

  // Find where: the lowest rank with a bad point tells everyone.
  std::vector<Field*> fields;
  double limit = config_.divergence_limit;
  if (velocity_bad) fields = state_.all(), limit = config_.velocity_limit;
  else fields = {&work_.div};
  char where[256] = "";
  for (Field* f : fields) {
    const Int3 n = f->n();
    const bool bounded = !velocity_bad || f->stagger() == Stagger::face_x || f->stagger() == Stagger::face_y ||
                         f->stagger() == Stagger::face_z;
    for (int k = 0; k < n[Z] && !where[0]; ++k)
      for (int j = 0; j < n[Y] && !where[0]; ++j)
        for (int i = 0; i < n[X] && !where[0]; ++i) {
          const double x = (*f)(i, j, k);
          if (!std::isfinite(x) || (bounded && std::fabs(x) > limit))
            std::snprintf(where, sizeof where, "%s = %g at global cell (%d, %d, %d)", f->name().c_str(), x,
                          f->offset()[X] + i, f->offset()[Y] + j, f->offset()[Z] + k);
        }
    if (where[0]) break;
  }
  int mine = where[0] ? decomp_.rank() : decomp_.size(), first = 0;
  MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, decomp_.comm());
  if (first < decomp_.size()) MPI_Bcast(where, sizeof where, MPI_CHAR, first, decomp_.comm());
  const std::string what = velocity_bad ? "max |velocity| = " + std::to_string(global[0])
                                        : "max |rho div v*| = " + std::to_string(global[1]);
  throw BlowUp("blow-up at step " + std::to_string(steps_) + " (t = " + std::to_string(time_) + "): " + what +
               " beyond the limit " + std::to_string(limit) + (where[0] ? std::string("; ") + where : std::string()));
}

FlowDiagnostics FsiSolver::diagnostics() {
  complete_exchange();
  FlowDiagnostics d = flow_diagnostics(state_, config_.physics);
  d.step = steps_;
  d.time = time_;
  const PressureReport& r = pressure_->report();
  d.beta = r.beta;
  d.gamma = r.gamma;
  if (d.beta > 0) d.mach = d.u_max / d.beta;
  const double eta = d.u_max * config_.dt / state_.domain().spacing(X);
  d.mach_bound = 2.0 * std::sqrt(3.0 * eta);
  return d;
}

}  // namespace efsi
