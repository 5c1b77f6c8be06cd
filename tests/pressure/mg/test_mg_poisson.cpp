// The multigrid Poisson solve (docs/numerics.md, "Multigrid solver"): to a relative residual
// of 1e-10 it gives the exact FFT solver's dp within 1e-8 of max |dp| on every decomposition
// of the started ranks, on a grid of three different spacings; the tolerance and the fixed
// cycle count stop it as asked; the time inside hypre's MPI calls counts as communication;
// the periodic sizes PFMG cannot coarsen are refused with the size and the rule.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "config_error.hpp"
#include "decomposition.hpp"
#include "domain.hpp"
#include "fft_poisson.hpp"
#include "field.hpp"
#include "mg_poisson.hpp"
#include "mpi_test_support.hpp"
#include "region_timers.hpp"

using namespace efsi;
using namespace efsi::testing;

namespace {

// A smooth right-hand side with x, y and z structure and a non-zero mean (which the solves
// remove).
void fill_rhs(Field& f, const Domain& d) {
  constexpr double pi = std::numbers::pi;
  const Int3 g = d.cells;
  for (int k = 0; k < f.n()[Z]; ++k)
    for (int j = 0; j < f.n()[Y]; ++j)
      for (int i = 0; i < f.n()[X]; ++i) {
        const double x = (f.offset()[X] + i + 0.5) / g[X], y = (f.offset()[Y] + j + 0.5) / g[Y],
                     z = (f.offset()[Z] + k + 0.5) / g[Z];
        f(i, j, k) = std::sin(2 * pi * x + 0.3) * std::cos(pi * y) + 0.5 * std::cos(4 * pi * z) * std::cos(2 * pi * y) +
                     0.2 * std::sin(6 * pi * x) * std::sin(2 * pi * z) + 0.1;
      }
}

double max_over_ranks(double v, MPI_Comm comm) {
  double m = 0;
  MPI_Allreduce(&v, &m, 1, MPI_DOUBLE, MPI_MAX, comm);
  return m;
}

// max |x - ref| and max |ref| over the owned cells of every rank.
struct Difference {
  double diff = 0, size = 0;
};
Difference difference(const Field& x, const Field& ref, const CartDecomposition& dec) {
  Difference d;
  for (int k = 0; k < dec.local()[Z]; ++k)
    for (int j = 0; j < dec.local()[Y]; ++j)
      for (int i = 0; i < dec.local()[X]; ++i) {
        d.diff = std::max(d.diff, std::fabs(x(i, j, k) - ref(i, j, k)));
        d.size = std::max(d.size, std::fabs(ref(i, j, k)));
      }
  return {max_over_ranks(d.diff, dec.comm()), max_over_ranks(d.size, dec.comm())};
}

}  // namespace

TEST(MgPoisson, AgreesWithTheFftSolveOnEveryDecomposition) {
  const Domain dom{{32, 24, 16}, {2.0, 1.5, 0.7}};  // dx = dy = 0.0625, dz = 0.04375
  const auto decs = fitting_decompositions(world_size(), dom.cells, 2);
  ASSERT_FALSE(decs.empty());
  for (const Int3& dims : decs) {
    SCOPED_TRACE(to_string(dims));
    CartDecomposition dec(MPI_COMM_WORLD, dom.cells, 1, dims);
    Field rhs(dec, {"rhs", Stagger::cell, 1}), mg_x(dec, {"x", Stagger::cell, 1}), fft_x(dec, {"y", Stagger::cell, 1});
    fill_rhs(rhs, dom);
    FftPoisson fft(dec, dom, FftPoisson::Planning::estimate);
    fft.solve(rhs, fft_x, 2.5);
    MgPoisson mg(dec, dom);
    const MgResult r = mg.solve(rhs, mg_x, 2.5, MgStop{1e-10, 200});
    EXPECT_LE(r.residual, 1e-10);
    EXPECT_GT(r.cycles, 1);
    const auto [diff, size] = difference(mg_x, fft_x, dec);
    if (world_rank() == 0)
      std::printf("  %s: %d V-cycles, residual %.2e, max |dp_mg - dp_fft| = %.2e of max |dp_fft|\n",
                  to_string(dims).c_str(), r.cycles, r.residual, diff / size);
    EXPECT_GT(size, 0.0);
    EXPECT_LT(diff, 1e-8 * size);
  }
}

// The solvers the benchmarks compare PFMG with reach the same answer.
TEST(MgPoisson, SmgAndPreconditionedCgAgreeWithTheFftSolve) {
  const Domain dom{{32, 24, 16}, {2.0, 1.5, 0.7}};
  CartDecomposition dec(MPI_COMM_WORLD, dom.cells, 1, {0, 0, 0});
  Field rhs(dec, {"rhs", Stagger::cell, 1}), x(dec, {"x", Stagger::cell, 1}), ref(dec, {"ref", Stagger::cell, 1});
  fill_rhs(rhs, dom);
  FftPoisson(dec, dom, FftPoisson::Planning::estimate).solve(rhs, ref, 1.0);
  for (MgSolver kind : {MgSolver::smg, MgSolver::pcg_pfmg}) {
    SCOPED_TRACE(to_string(kind));
    MgPoisson mg(dec, dom, nullptr, kind);
    const MgResult r = mg.solve(rhs, x, 1.0, MgStop{1e-8, 200});
    EXPECT_LE(r.residual, 1e-8);
    const auto [diff, size] = difference(x, ref, dec);
    EXPECT_LT(diff, 1e-6 * size);
  }
}

TEST(MgPoisson, StopsAtTheToleranceOrAfterTheCycles) {
  const Domain dom{{64, 32, 32}, {3.6, 1.8, 1.8}};
  CartDecomposition dec(MPI_COMM_WORLD, dom.cells, 1, {0, 0, 0});
  Field rhs(dec, {"rhs", Stagger::cell, 1}), x(dec, {"x", Stagger::cell, 1});
  fill_rhs(rhs, dom);
  MgPoisson mg(dec, dom);
  const MgResult loose = mg.solve(rhs, x, 1.0, MgStop{1e-3, 1000});
  EXPECT_LE(loose.residual, 1e-3);
  EXPECT_GE(loose.cycles, 1);
  const MgResult tight = mg.solve(rhs, x, 1.0, MgStop{1e-8, 1000});
  EXPECT_LE(tight.residual, 1e-8);
  EXPECT_GT(tight.cycles, loose.cycles);
  const MgResult fixed = mg.solve(rhs, x, 1.0, MgStop{0.0, 3});
  EXPECT_EQ(fixed.cycles, 3);
  EXPECT_GT(fixed.residual, tight.residual);
  // The zero mean, as the FFT solve returns it.
  double sum = 0;
  for (int k = 0; k < dec.local()[Z]; ++k)
    for (int j = 0; j < dec.local()[Y]; ++j)
      for (int i = 0; i < dec.local()[X]; ++i) sum += x(i, j, k);
  double total = 0;
  MPI_Allreduce(&sum, &total, 1, MPI_DOUBLE, MPI_SUM, dec.comm());
  EXPECT_LT(std::fabs(total) / double(product(dom.cells)), 1e-12);
}

// hypre's own exchanges and reductions reach the timers as communication (PMPI
// interposition): on more than one rank the solve spends time inside MPI, and the two
// regions together are the solve's time.
TEST(MgPoisson, TimeInsideMpiCountsAsCommunication) {
  const Domain dom{{64, 32, 32}, {3.6, 1.8, 1.8}};
  CartDecomposition dec(MPI_COMM_WORLD, dom.cells, 1, {0, 0, 0});
  Field rhs(dec, {"rhs", Stagger::cell, 1}), x(dec, {"x", Stagger::cell, 1});
  fill_rhs(rhs, dom);
  RegionTimers timers;
  MgPoisson mg(dec, dom, &timers);
  const double t0 = MPI_Wtime();
  mg.solve(rhs, x, 1.0, MgStop{1e-6, 1000});
  const double wall = MPI_Wtime() - t0;
  EXPECT_TRUE(is_communication(kMgMpiRegion));
  EXPECT_FALSE(is_communication(kMgSolveRegion));
  EXPECT_GT(timers.get(kMgSolveRegion), 0.0);
  if (world_size() > 1) {
    EXPECT_GT(timers.get(kMgMpiRegion), 0.0);
  }
  EXPECT_LE(timers.get(kMgSolveRegion) + timers.get(kMgMpiRegion), wall * (1 + 1e-9));
}

TEST(MgPoisson, RefusesPeriodicSizesItCannotCoarsen) {
  for (const Int3& g : {Int3{66, 64, 64}, Int3{64, 64, 100}, Int3{1, 8, 8}}) {
    const std::string e = config_error_of([&] { check_mg_grid(g); });
    SCOPED_TRACE(e);
    EXPECT_NE(e.find(g[X] == 64 ? "Nz=100" : "Nx=" + std::to_string(g[X])), std::string::npos);
    EXPECT_NE(e.find("2^k or 3 x 2^k"), std::string::npos);
  }
  for (const Int3& g : {Int3{64, 64, 64}, Int3{96, 7, 128}, Int3{6, 8, 6}})
    EXPECT_EQ(config_error_of([&] { check_mg_grid(g); }), "<no ConfigError thrown>");
}
