// The exact FFT + tridiagonal Poisson solver (docs/numerics.md, "Exact FFT solver"): on every decomposition the
// started rank count can make of several grids (non-cubic, non power-of-two, non-cubic
// spacing), the solution of a manufactured problem satisfies the discrete 7-point equation
// to round-off, equals the manufactured field (zero mean), and does not depend on the
// decomposition (every rank compares its block with a one-rank solve on MPI_COMM_SELF).
#include <gtest/gtest.h>
#include <mpi.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "acm.hpp"
#include "decomposition.hpp"
#include "domain.hpp"
#include "fft_poisson.hpp"
#include "field.hpp"
#include "halo_exchange.hpp"
#include "mpi_test_support.hpp"

using namespace efsi;

namespace {

// Smooth modes (periodic in x, z; cosine in y) plus a hash-based non-smooth part.
double raw_value(const Int3& g, const Int3& gi) {
  constexpr double pi = std::numbers::pi;
  const double x = (gi[X] + 0.5) / g[X], y = (gi[Y] + 0.5) / g[Y], z = (gi[Z] + 0.5) / g[Z];
  double v = std::sin(2 * pi * x) * std::cos(pi * y) + 0.7 * std::cos(4 * pi * z + 0.3) * y * y +
             0.4 * std::sin(2 * pi * (x + 2 * z)) * std::cos(3 * pi * y);
  std::uint64_t h = (std::uint64_t(gi[X]) * 73856093u) ^ (std::uint64_t(gi[Y]) * 19349663u) ^
                    (std::uint64_t(gi[Z]) * 83492791u);
  h ^= h >> 13;
  h *= 0x9E3779B97F4A7C15ull;
  h ^= h >> 29;
  v += 0.5 * (double(h % 100000) / 100000.0 - 0.5);
  return v;
}

// The same mean on every rank and decomposition: summed over the whole grid in one order.
double global_mean(const Int3& g) {
  double s = 0;
  for (int k = 0; k < g[Z]; ++k)
    for (int j = 0; j < g[Y]; ++j)
      for (int i = 0; i < g[X]; ++i) s += raw_value(g, {i, j, k});
  return s / double(product(g));
}

struct Problem {
  Field exact, rhs, x;
  double rhs_max = 0;
  Problem(const CartDecomposition& dec, const Domain& dom, double mean)
      : exact(dec, {"exact", Stagger::cell, 1, WallParity::even}),
        rhs(dec, {"rhs", Stagger::cell, 1, WallParity::even}),
        x(dec, {"x", Stagger::cell, 1, WallParity::even}) {
    const Int3& n = dec.local();
    for (int k = 0; k < n[Z]; ++k)
      for (int j = 0; j < n[Y]; ++j)
        for (int i = 0; i < n[X]; ++i)
          exact(i, j, k) =
              raw_value(dom.cells, {dec.offset()[X] + i, dec.offset()[Y] + j, dec.offset()[Z] + k}) - mean;
    HaloExchange hx(dec, {&exact}, Reach::faces);
    hx.exchange();
    const double inv_h2[3] = {1 / (dom.spacing(X) * dom.spacing(X)), 1 / (dom.spacing(Y) * dom.spacing(Y)),
                              1 / (dom.spacing(Z) * dom.spacing(Z))};
    rhs.fill(0.0);
    x.fill(0.0);
    for (int k = 0; k < n[Z]; ++k)
      for (int j = 0; j < n[Y]; ++j)
        for (int i = 0; i < n[X]; ++i) {
          rhs(i, j, k) = laplacian(exact, inv_h2, i, j, k);
          rhs_max = std::max(rhs_max, std::abs(rhs(i, j, k)));
        }
    MPI_Allreduce(MPI_IN_PLACE, &rhs_max, 1, MPI_DOUBLE, MPI_MAX, dec.comm());
  }
};

struct Errors {
  double residual, error, mean;
};

// max |Lap x - rhs| / max |rhs|, max |x - exact| / max |exact|, |<x>|.
Errors measure(const CartDecomposition& dec, const Domain& dom, Problem& p) {
  HaloExchange hx(dec, {&p.x}, Reach::faces);
  hx.exchange();
  const double inv_h2[3] = {1 / (dom.spacing(X) * dom.spacing(X)), 1 / (dom.spacing(Y) * dom.spacing(Y)),
                            1 / (dom.spacing(Z) * dom.spacing(Z))};
  double v[4] = {0, 0, 0, 0};  // residual, error, exact max, sum
  const Int3& n = dec.local();
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) {
        v[0] = std::max(v[0], std::abs(laplacian(p.x, inv_h2, i, j, k) - p.rhs(i, j, k)));
        v[1] = std::max(v[1], std::abs(p.x(i, j, k) - p.exact(i, j, k)));
        v[2] = std::max(v[2], std::abs(p.exact(i, j, k)));
        v[3] += p.x(i, j, k);
      }
  double sum = v[3];
  MPI_Allreduce(MPI_IN_PLACE, v, 3, MPI_DOUBLE, MPI_MAX, dec.comm());
  MPI_Allreduce(MPI_IN_PLACE, &sum, 1, MPI_DOUBLE, MPI_SUM, dec.comm());
  return {v[0] / p.rhs_max, v[1] / v[2], std::abs(sum) / double(product(dom.cells))};
}

void check_grid(const Domain& dom) {
  int p = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &p);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const double mean = global_mean(dom.cells);

  // One-rank reference, on every rank (each compares its own block with it).
  CartDecomposition self(MPI_COMM_SELF, dom.cells, 1, {1, 1, 1});
  Problem ref(self, dom, mean);
  FftPoisson ref_solver(self, dom, FftPoisson::Planning::estimate);
  ref_solver.solve(ref.rhs, ref.x);
  const Errors e_ref = measure(self, dom, ref);
  EXPECT_LT(e_ref.residual, 1e-10) << "one-rank " << to_string(dom.cells);
  EXPECT_LT(e_ref.error, 1e-9) << "one-rank " << to_string(dom.cells);
  double ref_max = 0;
  for (int k = 0; k < dom.cells[Z]; ++k)
    for (int j = 0; j < dom.cells[Y]; ++j)
      for (int i = 0; i < dom.cells[X]; ++i) ref_max = std::max(ref_max, std::abs(ref.x(i, j, k)));

  const auto decs = efsi::testing::fitting_decompositions(p, dom.cells, 1);
  ASSERT_FALSE(decs.empty());
  for (const Int3& dims : decs) {
    CartDecomposition dec(MPI_COMM_WORLD, dom.cells, 1, dims);
    const std::string where = "grid " + to_string(dom.cells) + " decomposition " + to_string(dims);
    Problem prob(dec, dom, mean);
    FftPoisson solver(dec, dom, FftPoisson::Planning::estimate);
    solver.solve(prob.rhs, prob.x);
    const Errors e = measure(dec, dom, prob);
    EXPECT_LT(e.residual, 1e-10) << where;
    EXPECT_LT(e.error, 1e-9) << where;
    EXPECT_LT(e.mean, 1e-12 * ref_max) << where;

    double diff = 0;
    const Int3& n = dec.local();
    for (int k = 0; k < n[Z]; ++k)
      for (int j = 0; j < n[Y]; ++j)
        for (int i = 0; i < n[X]; ++i)
          diff = std::max(diff, std::abs(prob.x(i, j, k) - ref.x(dec.offset()[X] + i, dec.offset()[Y] + j,
                                                                   dec.offset()[Z] + k)));
    MPI_Allreduce(MPI_IN_PLACE, &diff, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    EXPECT_LT(diff, 1e-12 * ref_max) << where;

    // Solving twice with the same plans gives bitwise the same answer.
    Field again(dec, {"again", Stagger::cell, 1, WallParity::even});
    solver.solve(prob.rhs, again);
    bool same = true;
    for (int k = 0; k < n[Z]; ++k)
      for (int j = 0; j < n[Y]; ++j)
        for (int i = 0; i < n[X]; ++i) same = same && again(i, j, k) == prob.x(i, j, k);
    EXPECT_TRUE(same) << where;

    if (rank == 0)
      std::printf("[fft_poisson] %s: residual %.2e, error %.2e, |mean| %.1e, vs one rank %.2e\n", where.c_str(),
                  e.residual, e.error, e.mean, diff / ref_max);
    MPI_Barrier(MPI_COMM_WORLD);
  }
}

}  // namespace

TEST(FftPoisson, NonCubicGridEveryDecomposition) {
  check_grid({{16, 24, 8}, {1.0, 2.0, 0.5}});
}

TEST(FftPoisson, NonPowerOfTwoGridEveryDecomposition) {
  check_grid({{12, 10, 6}, {3.0, 1.0, 2.5}});
}

TEST(FftPoisson, PowerOfTwoCubeEveryDecomposition) {
  check_grid({{16, 16, 16}, {3.6, 3.6, 3.6}});
}

TEST(FftPoisson, OddSizesEveryDecomposition) {
  // Odd Nx (r2c with no Nyquist mode), odd Nz: only y can be split.
  check_grid({{9, 8, 15}, {1.0, 0.3, 2.0}});
}

TEST(FftPoisson, ThinGridWithEmptyPencils) {
  // Fewer y cells than Px and fewer kz than Px Py: some ranks hold empty pencils.
  check_grid({{4, 4, 2}, {1.0, 0.5, 0.25}});
}

TEST(FftPoisson, RhsMeanIsProjectedOut) {
  // A constant added to rhs is incompatible with zero-flux walls; the solver removes it.
  CartDecomposition dec(MPI_COMM_WORLD, {8, 8, 8}, 1);
  const Domain dom{{8, 8, 8}, {1.0, 1.0, 1.0}};
  Problem a(dec, dom, global_mean(dom.cells));
  Field shifted(dec, {"shifted", Stagger::cell, 1, WallParity::even}), xb(dec, {"xb", Stagger::cell, 1, WallParity::even});
  const Int3& n = dec.local();
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) shifted(i, j, k) = a.rhs(i, j, k) + 3.0;
  FftPoisson solver(dec, dom, FftPoisson::Planning::estimate);
  solver.solve(a.rhs, a.x);
  solver.solve(shifted, xb);
  double diff = 0;
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) diff = std::max(diff, std::abs(a.x(i, j, k) - xb(i, j, k)));
  MPI_Allreduce(MPI_IN_PLACE, &diff, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  EXPECT_LT(diff, 1e-12);
}

TEST(FftPoisson, TimingAt64Cubed) {
  // For information only: no assertion on the time.
  int p = 1, rank = 0;
  MPI_Comm_size(MPI_COMM_WORLD, &p);
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  const Domain dom{{64, 64, 64}, {3.6, 3.6, 3.6}};
  CartDecomposition dec(MPI_COMM_WORLD, dom.cells, 1);
  Problem prob(dec, dom, 0.0);
  FftPoisson solver(dec, dom, FftPoisson::Planning::estimate);
  std::vector<double> t;
  for (int r = 0; r < 5; ++r) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double t0 = MPI_Wtime();
    solver.solve(prob.rhs, prob.x);
    double dt = MPI_Wtime() - t0;
    MPI_Allreduce(MPI_IN_PLACE, &dt, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
    t.push_back(dt);
  }
  std::sort(t.begin(), t.end());
  const Errors e = measure(dec, dom, prob);
  EXPECT_LT(e.residual, 1e-10);
  if (rank == 0)
    std::printf("[fft_poisson] 64^3 on %d ranks (%s) x %d threads: median solve %.2f ms, residual %.2e\n", p,
                to_string(dec.dims()).c_str(), omp_get_max_threads(), 1e3 * t[t.size() / 2], e.residual);
}
