// The solid cut-off (docs/numerics.md, "Solid cut-off"): where phi is below it, one step
// leaves Bt unstrained (isotropic, sqrt(phi_new) on the diagonal, no shear) and therefore no
// solid stress; everywhere else the step is bitwise the step without it; sync and async
// agree bitwise with it on.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "constitutive.hpp"
#include "mpi_test_support.hpp"
#include "solver_fixtures.hpp"
#include "stencils.hpp"

using namespace efsi;
using namespace efsi::testing;

namespace {

constexpr double kCutoff = 0.02;

// The paper's block with its two particles at 24^3, sheared by the driving force for 40
// steps so that the particles' debris carries strained Bt.
SolverConfig sheared_config(double cutoff, CommMode mode = CommMode::sync) {
  SolverConfig cfg;
  cfg.dt = 2e-3;
  cfg.physics.force = 20.0;
  cfg.physics.solid_cutoff = cutoff;
  cfg.comm = mode;
  return cfg;
}

Channel sheared_channel(MPI_Comm comm, double cutoff, CommMode mode = CommMode::sync, int steps = 40) {
  Channel c = make_channel(comm, paper_block(24), {0, 0, 0}, sheared_config(cutoff, mode), 2);
  for (int s = 0; s < steps; ++s) c.solver->step();
  c.solver->complete_exchange();
  return c;
}

// Owned points of a field, as the loops in the test visit them.
template <class F>
void for_owned(const Field& f, F&& body) {
  for (int k = 0; k < f.owned_end(Z); ++k)
    for (int j = 0; j < f.owned_end(Y); ++j)
      for (int i = 0; i < f.owned_end(X); ++i) body(i, j, k);
}

// Counts the points where `ok` fails and remembers the first, for one failure line per check.
struct Mismatches {
  long count = 0;
  std::string first;
  void check(bool ok, const std::string& what, int i, int j, int k) {
    if (ok) return;
    if (count++ == 0) first = what + " at " + std::to_string(i) + "," + std::to_string(j) + "," + std::to_string(k);
  }
};

bool same_bits(double x, double y) { return std::memcmp(&x, &y, sizeof x) == 0; }

template <Stagger T>
double phi_at(const Field& phi, int i, int j, int k) {
  return average<Stagger::cell, T>(phi, i, j, k);
}

double phi_at(int component, const Field& phi, int i, int j, int k) {
  switch (component) {
    case 3: return phi_at<Stagger::edge_xy>(phi, i, j, k);
    case 4: return phi_at<Stagger::edge_xz>(phi, i, j, k);
    case 5: return phi_at<Stagger::edge_yz>(phi, i, j, k);
    default: return phi(i, j, k);
  }
}

}  // namespace

// One step from the same sheared state, with and without the cut-off: below it every Bt
// component is the unstrained value; above it, and in every other field, bitwise the same.
// (With the cut-off the transport leaves the debris at each line's ends uncomputed: a kept
// point it skipped would differ here.)
TEST(SolidCutoff, ResetsTheDebrisAndNothingElse) {
  Channel with = sheared_channel(MPI_COMM_WORLD, kCutoff);
  Channel without = make_channel(MPI_COMM_WORLD, paper_block(24), {0, 0, 0}, sheared_config(0.0), 2);
  const std::vector<Field*> src = with.solver->state().all(), dst = without.solver->state().all();
  for (std::size_t f = 0; f < src.size(); ++f) dst[f]->copy_from(*src[f]);
  without.solver->resume(with.solver->steps_done(), with.solver->time());

  Field phi_before(*with.decomp, fsi_field_specs()[4]);
  phi_before.copy_from(with.solver->state().phi());
  with.solver->step();
  without.solver->step();
  with.solver->complete_exchange();
  without.solver->complete_exchange();

  const FsiState &a = with.solver->state(), &b = without.solver->state();
  long debris = 0, strained_debris = 0, solid = 0;
  Mismatches reset, kept, others;
  for (int c = 0; c < 6; ++c) {
    for_owned(a.B(c), [&](int i, int j, int k) {
      const double x = a.B(c)(i, j, k), y = b.B(c)(i, j, k);
      if (phi_at(c, phi_before, i, j, k) < kCutoff) {
        ++debris;
        const double unstrained = c < 3 ? sqrt_phi(a.phi()(i, j, k)) : 0.0;
        reset.check(same_bits(x, unstrained), a.B(c).name(), i, j, k);
        if (std::fabs(y - unstrained) > 1e-6) ++strained_debris;
      } else {
        ++solid;
        kept.check(same_bits(x, y), a.B(c).name(), i, j, k);
      }
    });
  }
  const std::vector<const Field*> fa = {&a.vel(X), &a.vel(Y), &a.vel(Z), &a.p(), &a.phi()};
  const std::vector<const Field*> fb = {&b.vel(X), &b.vel(Y), &b.vel(Z), &b.p(), &b.phi()};
  for (std::size_t f = 0; f < fa.size(); ++f)
    for_owned(*fa[f], [&](int i, int j, int k) {
      others.check(same_bits((*fa[f])(i, j, k), (*fb[f])(i, j, k)), fa[f]->name(), i, j, k);
    });
  EXPECT_EQ(reset.count, 0) << "debris not reset to unstrained, first: " << reset.first;
  EXPECT_EQ(kept.count, 0) << "solid changed by the cut-off, first: " << kept.first;
  EXPECT_EQ(others.count, 0) << "other fields changed by the cut-off, first: " << others.first;
  long counts[3] = {debris, strained_debris, solid}, total[3];
  MPI_Allreduce(counts, total, 3, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  // The case must exercise both sides: debris that the step without the cut-off strains, and solid.
  EXPECT_GT(total[1], 100);
  EXPECT_GT(total[2], 1000);
}

// With the cut-off, the debris carries no normal solid stress: after many steps the three
// diagonal Bt components are equal at every centre well below it (the edges are checked
// after one step above).
TEST(SolidCutoff, DebrisCarriesNoSolidStress) {
  Channel c = sheared_channel(MPI_COMM_WORLD, kCutoff, CommMode::sync, 60);
  const FsiState& s = c.solver->state();
  const Field& phi = s.phi();
  // phi has moved on by one update since the decision; sqrt(phi) I is the reset value of the
  // current phi, so the deviator is zero wherever the current phi is well below the cut-off.
  long checked = 0;
  Mismatches strained;
  for_owned(phi, [&](int i, int j, int k) {
    if (phi(i, j, k) >= 0.5 * kCutoff) return;
    ++checked;
    const double b11 = s.B(0)(i, j, k), b22 = s.B(1)(i, j, k), b33 = s.B(2)(i, j, k);
    strained.check(b11 == b22 && b11 == b33, "Bt diagonal", i, j, k);
  });
  EXPECT_EQ(strained.count, 0) << "debris with a deviatoric Bt, first: " << strained.first;
  EXPECT_GT(checked, 1000);
}

// Sync and async agree bitwise with the cut-off on, on the started ranks.
TEST(SolidCutoff, SyncAndAsyncAgreeBitwise) {
  Channel sync = sheared_channel(MPI_COMM_WORLD, kCutoff, CommMode::sync, 20);
  Channel async = sheared_channel(MPI_COMM_WORLD, kCutoff, CommMode::async, 20);
  const std::vector<Field*> a = sync.solver->state().all(), b = async.solver->state().all();
  Mismatches differ;
  for (std::size_t f = 0; f < a.size(); ++f)
    for_owned(*a[f], [&](int i, int j, int k) {
      differ.check(same_bits((*a[f])(i, j, k), (*b[f])(i, j, k)), a[f]->name(), i, j, k);
    });
  EXPECT_EQ(differ.count, 0) << "sync and async differ, first: " << differ.first;
}
