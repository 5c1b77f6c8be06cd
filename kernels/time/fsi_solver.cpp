#include "fsi_solver.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "compute_model.hpp"
#include "kernel_costs.hpp"

namespace efsi {

FsiSolver::FsiSolver(const CartDecomposition& decomp, const Domain& domain, const SolverConfig& config,
                     std::unique_ptr<PressureMethod> pressure)
    : decomp_(decomp),
      config_(config),
      integrator_(find_integrator(config.integrator)),
      state_(decomp, domain),
      work_(decomp),
      pressure_(std::move(pressure)) {
  if (config_.divergence_limit <= 0.0)
    config_.divergence_limit =
        0.005 * config_.velocity_limit / std::min({domain.spacing(X), domain.spacing(Y), domain.spacing(Z)});
  for (const StepExchangeSpec& x : kStepExchanges)
    halos_[static_cast<int>(x.id)] = std::make_unique<HaloExchange>(
        decomp, step_exchange_fields(x.id, state_, work_),
        x.reach == Reach::full ? full_reach(config_.halo) : x.reach, &timers_);
  // A periodic wrap onto this rank itself is copied when the exchange begins: the
  // interior may run up to those faces, and their strided shells (x) are not needed.
  const HaloExchange& state_halo = *halos_[static_cast<int>(StepExchange::state)];
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side) current_sides_[a][side] = state_halo.face_current_at_begin(a, 2 * side - 1);
  if (config_.cn_sweeps > 0) cn_ = std::make_unique<CrankNicolsonStress>(decomp, work_, config_.cn_sweeps, &timers_,
                                                                  full_reach(config_.halo));
  else fused_ = std::make_unique<StressAndMomentum>(work_.tau);  // Crank-Nicolson reads tau whole
  if (integrator_.stages.size() > 1) start_ = std::make_unique<FsiState>(decomp, domain);
  pressure_->attach(decomp, domain, work_, timers_);
}

void FsiSolver::post(StepExchange x) {
  HaloExchange& h = *halos_[static_cast<int>(x)];
  // With every neighbour this rank itself there is no message to overlap: the exchange
  // completes here in either mode, and the stages run whole instead of interior and shell.
  if (config_.comm == CommMode::sync || h.messages_sent() == 0) {
    h.exchange();
  } else {
    h.begin();
    pending_[static_cast<int>(x)] = true;
  }
}

void FsiSolver::complete(StepExchange x) {
  if (!in_flight(x)) return;
  halos_[static_cast<int>(x)]->finish();
  pending_[static_cast<int>(x)] = false;
}

void FsiSolver::complete_exchange() { complete(StepExchange::state); }

void FsiSolver::start_from_rest() {
  complete_exchange();
  state_.set_unstrained_rest();
  halos_[static_cast<int>(StepExchange::state)]->exchange();
  steps_ = 0;
  time_ = 0.0;
}

void FsiSolver::resume(long steps_done, double time) {
  complete_exchange();
  halos_[static_cast<int>(StepExchange::state)]->exchange();
  steps_ = steps_done;
  time_ = time;
}

void FsiSolver::impose_laminar_flow() {
  complete_exchange();
  Field& u = state_.vel(X);
  const Domain& d = state_.domain();
  const double dy = d.spacing(Y), ly = d.length[Y], c = config_.physics.force / (2.0 * config_.physics.mu);
  const Int3 n = u.n();
  setup_stage([&] {
    for (int j = 0; j < n[Y]; ++j) {
      const double y = u.coord(Y, j) * dy;
      const double value = c * y * (ly - y);
      for (int k = 0; k < n[Z]; ++k)
        for (int i = 0; i < n[X]; ++i) u(i, j, k) = value;
    }
  });
  halos_[static_cast<int>(StepExchange::state)]->exchange();
}

void FsiSolver::step() {
  if (start_) {
    complete_exchange();
    const std::vector<Field*> now = state_.all(), start = start_->all();
    RegionTimers::Scope t(&timers_, Region::compute);
    for (std::size_t f = 0; f < now.size(); ++f) start[f]->copy_from(*now[f]);
  }
  const std::vector<IntegratorStage>& stages = integrator_.stages;
  SubstepResult r{};
  for (std::size_t st = 0; st < stages.size(); ++st) {
    r = euler_substep(stages[st]);
    if (st + 1 < stages.size()) post(StepExchange::state);  // the next stage reads its ghosts
  }
  ++steps_;
  time_ += config_.dt;
  // Before the next step's exchange is posted: a blow-up leaves nothing in flight.
  if (config_.check_every > 0 && steps_ % config_.check_every == 0) check_blow_up(r.umax, r.divmax);
  post(StepExchange::state);
}

// The stages of one Euler sub-step, in order.  Where a stage reads ghosts of an exchange
// still in flight (async), it first does the points that read none (interior_boxes), then
// the rest once the exchange is complete; with the ghosts current it does all at once.
FsiSolver::SubstepResult FsiSolver::euler_substep(const IntegratorStage& stage) {
  const Int3 n = decomp_.local();
  const KernelBoxes full = full_boxes(n);
  const bool split = in_flight(StepExchange::state);
  // The x faces' ghosts are waited for first: the points next to an x face would otherwise
  // run after the wait as lines 1 to 3 points long or strided along y, at several times the
  // cost of a point in a whole row (measured: 2 ranks as 2x1x1, ACM, async 48 ms a step
  // against sync 32).  The interior then takes whole rows, and only y and z overlap.
  CurrentSides current = current_sides_;
  if (split && !(current[X][0] && current[X][1])) {
    halos_[static_cast<int>(StepExchange::state)]->finish_across(X);
    current[X] = {true, true};
  }
  const KernelBoxes in = split ? interior_boxes(n, current) : full;

  tendencies(in, !split);  // stress; v* = v + dt dv/dt; phi, Bt + dt d/dt and the solid cut-off
  complete(StepExchange::state);
  if (split) shell_stress_and_momentum(full, in);
  post(StepExchange::vstar);
  if (split) shell_transport(full, in);
  complete(StepExchange::vstar);
  // Its sweeps exchange v* in all 26 directions, the last one included.
  if (cn_) cn_->iterate(state_, work_, config_.physics, config_.dt);

  const double divmax = compute_divergence();  // D* = rho div v*
  post(StepExchange::divergence);
  complete(StepExchange::divergence);
  PressureInputs pin{state_, work_, config_.physics, config_.dt, timers_};
  pressure_->increment(pin);  // dp
  const double umax = project();  // v = v* - dt/rho grad dp, p += dp

  std::swap(state_.phi(), work_.phi_new);
  for (int c = 0; c < 6; ++c) std::swap(state_.B(c), work_.B_new[c]);
  blend_with_start(stage);
  return {umax, divmax};
}

// The simulation build charges each stage's counted work per cell of its box (the shells:
// the full box less the interior) instead of running it (compute_model.hpp).
void FsiSolver::tendencies(const KernelBoxes& b, bool whole) {
  RegionTimers::Scope t(&timers_, Region::compute);
  const FieldSet s = state_.fields();
  if (whole && fused_) {
    compute_stage(kStressAndMomentum, double(b.momentum.volume()),
                  [&] { fused_->run(s, config_.physics, work_.root_phi, work_.vstar, euler()); });
  } else {
    compute_stage(kStress + kMomentum, double(b.momentum.volume()), [&] {
      compute_stress(s, config_.physics, work_.root_phi, work_.tau, b.stress_centres, b.stress_edges);
      momentum_tendency(s, config_.physics, work_.tau, work_.vstar, b.momentum, euler());
    });
  }
  compute_stage(kTransport, double(b.transport.volume()), [&] {
    transport_tendency(s, work_.phi_new, work_.B_new, b.transport, config_.physics.solid_cutoff, euler());
  });
}

void FsiSolver::shell_transport(const KernelBoxes& full, const KernelBoxes& in) {
  RegionTimers::Scope t(&timers_, Region::compute);
  const FieldSet s = state_.fields();
  compute_stage(kTransport, double(full.transport.volume() - in.transport.volume()), [&] {
    for_each_shell_box(full.transport, in.transport, [&](const Box& b) {
      transport_tendency(s, work_.phi_new, work_.B_new, b, config_.physics.solid_cutoff, euler());
    });
  });
}

void FsiSolver::shell_stress_and_momentum(const KernelBoxes& full, const KernelBoxes& in) {
  RegionTimers::Scope t(&timers_, Region::compute);
  const FieldSet s = state_.fields();
  const Physics& ph = config_.physics;
  compute_stage(kStress + kMomentum, double(full.momentum.volume() - in.momentum.volume()), [&] {
    for_each_shell_box(full.stress_centres, in.stress_centres,
                       [&](const Box& b) { compute_stress(s, ph, work_.root_phi, work_.tau, b, Box{}); });
    for_each_shell_box(full.stress_edges, in.stress_edges,
                       [&](const Box& b) { compute_stress(s, ph, work_.root_phi, work_.tau, Box{}, b); });
    for_each_shell_box(full.momentum, in.momentum,
                       [&](const Box& b) { momentum_tendency(s, ph, work_.tau, work_.vstar, b, euler()); });
  });
}

void FsiSolver::blend_with_start(const IntegratorStage& stage) {
  if (!start_) return;
  RegionTimers::Scope t(&timers_, Region::compute);
  const std::vector<Field*> now = state_.all(), start = start_->all();
  for (std::size_t f = 0; f < now.size(); ++f) blend(*now[f], *start[f], stage);
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
  double result = 0.0;  // the lambda reduces its own local (see acm_moments)
  compute_stage(kDivergence, double(product(n)), [&] {
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
    result = dmax;
  });
  return result;
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
  double result = 0.0;  // the lambda reduces its own local (see acm_moments)
  compute_stage(kProject, double(product(n)), [&] {
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
    result = umax;
  });
  return result;
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
