#pragma once
// One step of the FSI equations (docs/numerics.md; its data flow in docs/architecture.md):
// the integrator's stages, each an Euler sub-step of the projection method (stress,
// momentum and transport tendencies, v*, D*, the method's pressure increment, projection)
// blended with the step's start.  Only the PressureMethod differs between ACM and the SMAC
// variants; only where exchanges complete differs between the halo modes.
#include <array>
#include <memory>
#include <string>

#include "comm_mode.hpp"
#include "crank_nicolson.hpp"
#include "fsi_equations.hpp"
#include "halo_exchange.hpp"
#include "integrator.hpp"
#include "pressure_method.hpp"
#include "step_exchanges.hpp"
#include "stepper.hpp"

namespace efsi {

struct SolverConfig {
  Physics physics;
  double dt = 1e-4;
  CommMode comm = CommMode::sync;
  // How the exchanges that fill every ghost (the state's, Crank-Nicolson's v*) reach the
  // edges and corners: the same ghosts, bit for bit, either way (halo_exchange.hpp).
  HaloPattern halo = HaloPattern::direct;
  // A velocity component beyond this, a non-finite value, or a predicted divergence
  // rho div v* beyond divergence_limit stops the run (BlowUp). divergence_limit <= 0
  // means 0.005 velocity_limit / dx: with velocity_limit at 100 times the flow's scale U,
  // half of U / dx, a velocity field that is mostly compression.
  double velocity_limit = 1e3;
  double divergence_limit = 0.0;
  int check_every = 1;  // steps between blow-up checks (one MPI_Allreduce each)
  // 0: explicit Euler for the deviatoric stress (the paper's ACM and FFT reference);
  // N_C > 0: Crank-Nicolson by N_C fixed-point sweeps per step (the paper's SOR path).
  int cn_sweeps = 0;
  std::string integrator = "euler";  // a row of integrators() (integrator.hpp)
};

class FsiSolver final : public Stepper {
 public:
  FsiSolver(const CartDecomposition& decomp, const Domain& domain, const SolverConfig& config,
            std::unique_ptr<PressureMethod> pressure);

  // Set phi on the owned cells first; this puts the rest of the state at rest and
  // unstrained (Bt = sqrt(phi) I) and fills every ghost.
  void start_from_rest();
  // The steady laminar Poiseuille profile u = f y (Ly - y) / (2 mu) on top of the current
  // solid and stress (the particle-free steady state; a developed flow for the particles
  // to start in). Fills every ghost.
  void impose_laminar_flow();
  // After the owned points of every state field were set from a checkpoint: the step
  // count and time it was written at, and every ghost filled, so that the next step is the
  // one the checkpointed run took.
  void resume(long steps_done, double time);

  void step() override;
  FlowDiagnostics diagnostics() override;
  long steps_done() const override { return steps_; }
  double time() const override { return time_; }
  const RegionTimers& timers() const override { return timers_; }
  RegionTimers& timers() override { return timers_; }

  FsiState& state() { return state_; }
  const FsiState& state() const { return state_; }
  const SolverConfig& config() const { return config_; }
  const PressureMethod& pressure() const { return *pressure_; }
  const FsiWork& work() const { return work_; }  // D* and dp of the last step, for checks
  const CrankNicolsonStress* crank_nicolson() const { return cn_.get(); }  // null: explicit stress
  const Integrator& integrator() const { return integrator_; }
  // Completes an async exchange in flight so that every ghost is current.
  void complete_exchange();

 private:
  struct SubstepResult {
    double umax, divmax;  // local max |velocity| and |D*| (inf when non-finite)
  };
  SubstepResult euler_substep(const IntegratorStage& stage);
  // whole: the state's ghosts are all current (no interior and shell).
  void tendencies(const KernelBoxes& boxes, bool whole);
  void shell_stress_and_momentum(const KernelBoxes& full, const KernelBoxes& in);
  void shell_transport(const KernelBoxes& full, const KernelBoxes& in);
  // Each stage's Euler update, written by the momentum and transport kernels.
  RateOutput euler() const { return RateOutput::euler_update(config_.dt); }
  double compute_divergence();
  double project();
  void blend_with_start(const IntegratorStage& stage);
  void check_blow_up(double local_umax, double local_divmax);

  // The table's exchanges: sync completes one where it is posted, async where the first
  // stage that reads its ghosts needs them.
  void post(StepExchange x);
  void complete(StepExchange x);
  bool in_flight(StepExchange x) const { return pending_[static_cast<int>(x)]; }

  const CartDecomposition& decomp_;
  SolverConfig config_;
  const Integrator& integrator_;
  FsiState state_;
  FsiWork work_;
  std::unique_ptr<PressureMethod> pressure_;
  RegionTimers timers_;
  std::array<std::unique_ptr<HaloExchange>, kStepExchanges.size()> halos_;
  std::array<bool, kStepExchanges.size()> pending_{};
  CurrentSides current_sides_{};  // of the state exchange, for interior_boxes
  std::unique_ptr<CrankNicolsonStress> cn_;
  std::unique_ptr<StressAndMomentum> fused_;  // without Crank-Nicolson
  std::unique_ptr<FsiState> start_;  // u^n, for integrators of more than one stage
  long steps_ = 0;
  double time_ = 0.0;
};

}  // namespace efsi
