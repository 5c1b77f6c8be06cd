#include "mg_poisson.hpp"

#include <HYPRE_struct_ls.h>
#include <HYPRE_utilities.h>

#include <mutex>
#include <string>

#include "config_error.hpp"
#include "mpi_interpose.hpp"

namespace efsi {
namespace {

std::once_flag hypre_once;

// 3 * 2^k or 2^k, k >= 1.
bool coarsens(int n) {
  if (n < 2 || n % 2 != 0) return false;
  while (n % 2 == 0) n /= 2;
  return n == 1 || n == 3;
}

HYPRE_StructGrid G(void* p) { return static_cast<HYPRE_StructGrid>(p); }
HYPRE_StructMatrix M(void* p) { return static_cast<HYPRE_StructMatrix>(p); }
HYPRE_StructVector V(void* p) { return static_cast<HYPRE_StructVector>(p); }
HYPRE_StructSolver S(void* p) { return static_cast<HYPRE_StructSolver>(p); }

void check(HYPRE_Int err, const char* what) {
  if (err != 0 && !HYPRE_CheckError(err, HYPRE_ERROR_CONV))
    throw ConfigError(std::string("hypre: ") + what + " failed (error " + std::to_string(err) + ")");
  HYPRE_ClearAllErrors();
}

// The entry points a solve and the teardown call, the same for the three solvers.
struct SolverCalls {
  HYPRE_Int (*set_tol)(HYPRE_StructSolver, HYPRE_Real);
  HYPRE_Int (*set_max_iter)(HYPRE_StructSolver, HYPRE_Int);
  HYPRE_Int (*solve)(HYPRE_StructSolver, HYPRE_StructMatrix, HYPRE_StructVector, HYPRE_StructVector);
  HYPRE_Int (*iterations)(HYPRE_StructSolver, HYPRE_Int*);
  HYPRE_Int (*residual)(HYPRE_StructSolver, HYPRE_Real*);
  HYPRE_Int (*destroy)(HYPRE_StructSolver);
  const char* solve_name;
};

const SolverCalls& calls(MgSolver kind) {
  static const SolverCalls pfmg{HYPRE_StructPFMGSetTol, HYPRE_StructPFMGSetMaxIter, HYPRE_StructPFMGSolve,
                                HYPRE_StructPFMGGetNumIterations, HYPRE_StructPFMGGetFinalRelativeResidualNorm,
                                HYPRE_StructPFMGDestroy, "StructPFMGSolve"};
  static const SolverCalls smg{HYPRE_StructSMGSetTol, HYPRE_StructSMGSetMaxIter, HYPRE_StructSMGSolve,
                               HYPRE_StructSMGGetNumIterations, HYPRE_StructSMGGetFinalRelativeResidualNorm,
                               HYPRE_StructSMGDestroy, "StructSMGSolve"};
  static const SolverCalls pcg{HYPRE_StructPCGSetTol, HYPRE_StructPCGSetMaxIter, HYPRE_StructPCGSolve,
                               HYPRE_StructPCGGetNumIterations, HYPRE_StructPCGGetFinalRelativeResidualNorm,
                               HYPRE_StructPCGDestroy, "StructPCGSolve"};
  switch (kind) {
    case MgSolver::pfmg: return pfmg;
    case MgSolver::smg: return smg;
    case MgSolver::pcg_pfmg: return pcg;
  }
  return pfmg;
}

}  // namespace

void check_mg_grid(const Int3& cells) {
  for (int a : {X, Z})
    if (!coarsens(cells[a]))
      throw ConfigError(std::string("--method mg: N") + (a == X ? "x" : "z") + "=" + std::to_string(cells[a]) +
                        " is periodic, and hypre's PFMG coarsens a periodic axis only for N = 2^k or 3 x 2^k "
                        "(k >= 1; e.g. 64, 96, 128)");
}

const char* to_string(MgSolver s) {
  switch (s) {
    case MgSolver::pfmg: return "pfmg";
    case MgSolver::smg: return "smg";
    case MgSolver::pcg_pfmg: return "pcg-pfmg";
  }
  return "?";
}

MgPoisson::MgPoisson(const CartDecomposition& decomp, const Domain& domain, RegionTimers* timers, MgSolver kind)
    : decomp_(decomp), timers_(timers), kind_(kind) {
  check_mg_grid(decomp.global());
  std::call_once(hypre_once, [] { HYPRE_Init(); });
  const double t0 = MPI_Wtime();
  const Int3 n = decomp.local(), off = decomp.offset(), g = decomp.global();
  for (int a = 0; a < 3; ++a) lo_[a] = off[a], hi_[a] = off[a] + n[a] - 1;
  count_ = product(n);
  values_.assign(static_cast<std::size_t>(7 * count_), 0.0);
  MPI_Comm comm = decomp.comm();

  HYPRE_StructGrid grid;
  check(HYPRE_StructGridCreate(comm, 3, &grid), "StructGridCreate");
  grid_ = grid;
  check(HYPRE_StructGridSetExtents(grid, lo_.data(), hi_.data()), "StructGridSetExtents");
  HYPRE_Int periodic[3] = {g[X], 0, g[Z]};
  check(HYPRE_StructGridSetPeriodic(grid, periodic), "StructGridSetPeriodic");
  check(HYPRE_StructGridAssemble(grid), "StructGridAssemble");

  HYPRE_StructStencil stencil;
  check(HYPRE_StructStencilCreate(3, 7, &stencil), "StructStencilCreate");
  stencil_ = stencil;
  HYPRE_Int offsets[7][3] = {{0, 0, 0}, {-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  for (int e = 0; e < 7; ++e) check(HYPRE_StructStencilSetElement(stencil, e, offsets[e]), "StructStencilSetElement");

  // A = -Lap, symmetric positive semi-definite: across a wall the coefficient is dropped and
  // the diagonal shrinks, as in the SOR and FFT solvers.
  HYPRE_StructMatrix A;
  check(HYPRE_StructMatrixCreate(comm, grid, stencil, &A), "StructMatrixCreate");
  matrix_ = A;
  check(HYPRE_StructMatrixSetSymmetric(A, 0), "StructMatrixSetSymmetric");
  check(HYPRE_StructMatrixInitialize(A), "StructMatrixInitialize");
  double c[3];
  for (int a = 0; a < 3; ++a) c[a] = 1.0 / (domain.spacing(a) * domain.spacing(a));
  std::int64_t m = 0;
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j) {
      const int gj = off[Y] + j;
      const double below = gj > 0 ? c[Y] : 0.0, above = gj < g[Y] - 1 ? c[Y] : 0.0;
      for (int i = 0; i < n[X]; ++i, m += 7) {
        double* v = values_.data() + m;
        v[0] = 2 * c[X] + below + above + 2 * c[Z];
        v[1] = v[2] = -c[X];
        v[3] = -below;
        v[4] = -above;
        v[5] = v[6] = -c[Z];
      }
    }
  HYPRE_Int entries[7] = {0, 1, 2, 3, 4, 5, 6};
  check(HYPRE_StructMatrixSetBoxValues(A, lo_.data(), hi_.data(), 7, entries, values_.data()),
        "StructMatrixSetBoxValues");
  check(HYPRE_StructMatrixAssemble(A), "StructMatrixAssemble");

  HYPRE_StructVector b, x;
  check(HYPRE_StructVectorCreate(comm, grid, &b), "StructVectorCreate");
  b_ = b;
  check(HYPRE_StructVectorCreate(comm, grid, &x), "StructVectorCreate");
  x_ = x;
  for (HYPRE_StructVector v : {b, x}) {
    check(HYPRE_StructVectorInitialize(v), "StructVectorInitialize");
    check(HYPRE_StructVectorAssemble(v), "StructVectorAssemble");
  }
  std::vector<double>(static_cast<std::size_t>(count_)).swap(values_);  // the matrix's 7 per cell freed

  // PFMG as a trial on this operator found it fastest: red-black Gauss-Seidel, V(2,1), skip
  // relaxation on the coarse levels, non-Galerkin coarse operators.
  auto make_pfmg = [&](HYPRE_StructSolver& p, bool as_preconditioner) {
    check(HYPRE_StructPFMGCreate(comm, &p), "StructPFMGCreate");
    HYPRE_StructPFMGSetRelaxType(p, 2);
    HYPRE_StructPFMGSetNumPreRelax(p, 2);
    HYPRE_StructPFMGSetNumPostRelax(p, 1);
    HYPRE_StructPFMGSetSkipRelax(p, 1);
    HYPRE_StructPFMGSetRAPType(p, 1);
    HYPRE_StructPFMGSetRelChange(p, 0);
    HYPRE_StructPFMGSetZeroGuess(p);
    if (as_preconditioner) {
      HYPRE_StructPFMGSetMaxIter(p, 1);
      HYPRE_StructPFMGSetTol(p, 0.0);
    } else {
      HYPRE_StructPFMGSetLogging(p, 1);
    }
    HYPRE_StructPFMGSetPrintLevel(p, 0);
  };
  HYPRE_StructSolver solver = nullptr;
  switch (kind_) {
    case MgSolver::pfmg:
      make_pfmg(solver, false);
      solver_ = solver;
      check(HYPRE_StructPFMGSetup(solver, A, b, x), "StructPFMGSetup");
      break;
    case MgSolver::smg:
      check(HYPRE_StructSMGCreate(comm, &solver), "StructSMGCreate");
      solver_ = solver;
      HYPRE_StructSMGSetRelChange(solver, 0);
      HYPRE_StructSMGSetZeroGuess(solver);
      HYPRE_StructSMGSetNumPreRelax(solver, 1);
      HYPRE_StructSMGSetNumPostRelax(solver, 1);
      HYPRE_StructSMGSetLogging(solver, 1);
      check(HYPRE_StructSMGSetup(solver, A, b, x), "StructSMGSetup");
      break;
    case MgSolver::pcg_pfmg: {
      check(HYPRE_StructPCGCreate(comm, &solver), "StructPCGCreate");
      solver_ = solver;
      HYPRE_StructPCGSetTwoNorm(solver, 1);
      HYPRE_StructPCGSetRelChange(solver, 0);
      HYPRE_StructPCGSetLogging(solver, 1);
      HYPRE_StructSolver pre = nullptr;
      make_pfmg(pre, true);
      precond_ = pre;
      HYPRE_StructPCGSetPrecond(solver, HYPRE_StructPFMGSolve, HYPRE_StructPFMGSetup, pre);
      check(HYPRE_StructPCGSetup(solver, A, b, x), "StructPCGSetup");
      break;
    }
  }
  setup_seconds_ = MPI_Wtime() - t0;
}

MgPoisson::~MgPoisson() {
  if (solver_) calls(kind_).destroy(S(solver_));
  if (precond_) HYPRE_StructPFMGDestroy(S(precond_));
  if (x_) HYPRE_StructVectorDestroy(V(x_));
  if (b_) HYPRE_StructVectorDestroy(V(b_));
  if (matrix_) HYPRE_StructMatrixDestroy(M(matrix_));
  if (stencil_) HYPRE_StructStencilDestroy(static_cast<HYPRE_StructStencil>(stencil_));
  if (grid_) HYPRE_StructGridDestroy(G(grid_));
}

MgResult MgPoisson::solve(const Field& rhs, Field& x, double factor, const MgStop& stop) {
  const double t0 = MPI_Wtime(), mpi0 = mpi_seconds();
  const Int3 n = decomp_.local();
  // b = -factor (rhs - <rhs>): A is -Lap; the mean keeps the singular system compatible.
  double sum = 0.0;
  std::int64_t m = 0;
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) sum += (values_[static_cast<std::size_t>(m++)] = rhs(i, j, k));
  double total = 0.0;
  MPI_Allreduce(&sum, &total, 1, MPI_DOUBLE, MPI_SUM, decomp_.comm());
  const double mean = total / static_cast<double>(product(decomp_.global()));
  for (double& v : values_) v = -factor * (v - mean);
  check(HYPRE_StructVectorSetBoxValues(V(b_), lo_.data(), hi_.data(), values_.data()), "StructVectorSetBoxValues");
  std::fill(values_.begin(), values_.end(), 0.0);
  check(HYPRE_StructVectorSetBoxValues(V(x_), lo_.data(), hi_.data(), values_.data()), "StructVectorSetBoxValues");

  MgResult r;
  HYPRE_Int cycles = 0;
  const SolverCalls& c = calls(kind_);
  HYPRE_StructSolver sv = S(solver_);
  c.set_tol(sv, stop.tolerance);
  c.set_max_iter(sv, stop.max_cycles);
  check(c.solve(sv, M(matrix_), V(b_), V(x_)), c.solve_name);
  c.iterations(sv, &cycles);
  c.residual(sv, &r.residual);
  r.cycles = cycles;

  check(HYPRE_StructVectorGetBoxValues(V(x_), lo_.data(), hi_.data(), values_.data()), "StructVectorGetBoxValues");
  sum = 0.0;
  for (double v : values_) sum += v;
  MPI_Allreduce(&sum, &total, 1, MPI_DOUBLE, MPI_SUM, decomp_.comm());
  const double xmean = total / static_cast<double>(product(decomp_.global()));
  m = 0;
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) x(i, j, k) = values_[static_cast<std::size_t>(m++)] - xmean;
  if (timers_) {
    const double mpi = mpi_seconds() - mpi0;
    timers_->add(kMgMpiRegion, mpi);
    timers_->add(kMgSolveRegion, MPI_Wtime() - t0 - mpi);
  }
  return r;
}

}  // namespace efsi
