// The batched halo exchange, on every decomposition the started rank count can make of a
// small grid: after an exchange every ghost of every staggering, halo width and wall
// parity equals the global field (periodic in x and z) or the wall rule (mirror in y);
// sync and async leave bitwise identical fields.
#include <gtest/gtest.h>
#include <mpi.h>

#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include "comm_mode.hpp"
#include "decomposition.hpp"
#include "field.hpp"
#include "halo_exchange.hpp"
#include "mpi_test_support.hpp"

using namespace efsi;

namespace {

const Int3 kGlobal{24, 48, 24};  // divisible by 1, 2, 3, 4, 6 and 8 on every axis, >= 3 per rank
constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();

std::vector<FieldSpec> test_specs() {
  // The eleven FSI fields with their real layout ...
  std::vector<FieldSpec> s = {
      {"u", Stagger::face_x, 1, WallParity::odd},        {"v", Stagger::face_y, 1, WallParity::odd},
      {"w", Stagger::face_z, 1, WallParity::odd},        {"p", Stagger::cell, 1, WallParity::even},
      {"phi", Stagger::cell, 3, WallParity::even},       {"Bt11", Stagger::cell, 3, WallParity::even},
      {"Bt22", Stagger::cell, 3, WallParity::even},      {"Bt33", Stagger::cell, 3, WallParity::even},
      {"Bt12", Stagger::edge_xy, 3, WallParity::even},   {"Bt13", Stagger::edge_xz, 3, WallParity::even},
      {"Bt23", Stagger::edge_yz, 3, WallParity::even},
  };
  // ... and every other combination of staggering, width and parity.
  const Stagger all[] = {Stagger::cell,    Stagger::face_x,  Stagger::face_y, Stagger::face_z,
                         Stagger::edge_xy, Stagger::edge_xz, Stagger::edge_yz};
  for (Stagger st : all)
    for (int h : {1, 2, 3})
      for (WallParity par : {WallParity::even, WallParity::odd})
        s.push_back({std::string(to_string(st)) + "_h" + std::to_string(h) + (par == WallParity::odd ? "_odd" : "_even"),
                     st, h, par});
  return s;
}

// Exact in double: distinct integers for every (field, point).
double formula(int fid, int gi, int gj, int gk) { return 1.0 + fid + 64.0 * (gi + 64.0 * (gj + 64.0 * gk)); }

int wrap(int g, int n) { return ((g % n) + n) % n; }

// What a point at global index (gi, gj, gk) must hold: periodic in x and z, wall rule in y.
double expected(const Field& f, int fid, int gi, int gj, int gk) {
  gi = wrap(gi, kGlobal[X]);
  gk = wrap(gk, kGlobal[Z]);
  const int ny = kGlobal[Y];
  const bool odd = f.spec().parity == WallParity::odd;
  const double sign = odd ? -1.0 : 1.0;
  double s = 1.0;
  if (is_staggered(f.stagger(), Y)) {
    if (gj < 0) gj = -gj, s = sign;
    else if (gj > ny) gj = 2 * ny - gj, s = sign;
    if (odd && (gj == 0 || gj == ny)) return 0.0;
  } else {
    if (gj < 0) gj = -1 - gj, s = sign;
    else if (gj >= ny) gj = 2 * ny - 1 - gj, s = sign;
  }
  return s * formula(fid, gi, gj, gk);
}

struct FieldSet {
  std::vector<std::unique_ptr<Field>> owned;
  std::vector<Field*> ptrs;
  FieldSet(const CartDecomposition& dec, const std::vector<FieldSpec>& specs) {
    for (const auto& s : specs) {
      owned.push_back(std::make_unique<Field>(dec, s));
      ptrs.push_back(owned.back().get());
    }
    for (int fid = 0; fid < static_cast<int>(ptrs.size()); ++fid) {
      Field& f = *ptrs[fid];
      f.fill(kUnset);
      for (int k = 0; k < f.owned_end(Z); ++k)
        for (int j = 0; j < f.owned_end(Y); ++j)
          for (int i = 0; i < f.owned_end(X); ++i)
            f(i, j, k) = formula(fid, f.offset()[X] + i, f.offset()[Y] + j, f.offset()[Z] + k);
    }
  }
};

bool inside(const Field& f, int a, int i) { return i >= 0 && i < f.owned_end(a); }

// Counts wrong points among those the reach must fill (all, or owned plus face ghosts).
long long count_wrong(const FieldSet& set, Reach reach, const std::string& where) {
  long long wrong = 0;
  for (int fid = 0; fid < static_cast<int>(set.ptrs.size()); ++fid) {
    const Field& f = *set.ptrs[fid];
    const int h = f.halo();
    for (int k = -h; k < f.n()[Z] + h; ++k)
      for (int j = -h; j < f.n()[Y] + h; ++j)
        for (int i = -h; i < f.n()[X] + h; ++i) {
          const int outside = !inside(f, X, i) + !inside(f, Y, j) + !inside(f, Z, k);
          if (reach == Reach::faces && outside > 1) continue;
          const double want = expected(f, fid, f.offset()[X] + i, f.offset()[Y] + j, f.offset()[Z] + k);
          const double got = f(i, j, k);
          if (!(got == want)) {
            if (wrong < 3)
              ADD_FAILURE() << where << " field " << f.name() << " at local (" << i << "," << j << "," << k
                            << "): got " << got << ", want " << want;
            ++wrong;
          }
        }
  }
  return wrong;
}

bool bitwise_equal(const FieldSet& a, const FieldSet& b) {
  for (std::size_t n = 0; n < a.ptrs.size(); ++n)
    if (std::memcmp(a.ptrs[n]->data(), b.ptrs[n]->data(), a.ptrs[n]->allocated() * sizeof(double)) != 0)
      return false;
  return true;
}

// body(decomposition, the test fields' specs, a label) on every decomposition the started
// ranks can make of kGlobal, the ranks meeting after each.
template <class Body>
void for_each_decomposition(Body&& body) {
  int p = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &p);
  const auto specs = test_specs();
  for (const Int3& dims : efsi::testing::fitting_decompositions(p, kGlobal, 3)) {
    CartDecomposition dec(MPI_COMM_WORLD, kGlobal, 3, dims);
    body(dec, specs, "decomposition " + to_string(dims) + " rank " + std::to_string(dec.rank()));
    MPI_Barrier(MPI_COMM_WORLD);
  }
}

void check_all_decompositions(Reach reach) {
  for_each_decomposition([reach](const CartDecomposition& dec, const std::vector<FieldSpec>& specs,
                                 const std::string& where) {
    FieldSet sync_set(dec, specs), async_set(dec, specs);
    HaloExchange sync_x(dec, sync_set.ptrs, reach);
    HaloExchange async_x(dec, async_set.ptrs, reach);
    sync_x.exchange();
    async_x.begin();
    async_x.finish();

    EXPECT_EQ(count_wrong(sync_set, reach, where + " sync"), 0);
    EXPECT_EQ(count_wrong(async_set, reach, where + " async"), 0);
    EXPECT_TRUE(bitwise_equal(sync_set, async_set)) << where;

    // A second exchange of already-consistent fields changes nothing.
    async_x.begin();
    async_x.finish();
    EXPECT_TRUE(bitwise_equal(sync_set, async_set)) << where << " after a second exchange";
  });
}

}  // namespace

TEST(HaloExchange, FullReachFillsEveryGhostOnEveryDecomposition) { check_all_decompositions(Reach::full); }

TEST(HaloExchange, FaceReachFillsFaceGhostsOnEveryDecomposition) { check_all_decompositions(Reach::faces); }

TEST(HaloExchange, PhasedFullReachFillsEveryGhostOnEveryDecomposition) {
  check_all_decompositions(Reach::full_phased);
}

// The corners carried through the faces are the corners sent directly, bit for bit, in
// either mode, and the phased async form lets progress() move its rounds on.
TEST(HaloExchange, PhasedAndDirectLeaveBitwiseTheSameFields) {
  for_each_decomposition([](const CartDecomposition& dec, const std::vector<FieldSpec>& specs,
                            const std::string& where) {
    FieldSet direct(dec, specs), phased(dec, specs), phased_async(dec, specs);
    HaloExchange direct_x(dec, direct.ptrs, Reach::full), phased_x(dec, phased.ptrs, Reach::full_phased),
        async_x(dec, phased_async.ptrs, Reach::full_phased);
    direct_x.exchange();
    phased_x.exchange();
    async_x.begin();
    for (int i = 0; i < 4; ++i) async_x.progress();
    async_x.finish();
    EXPECT_TRUE(bitwise_equal(direct, phased)) << where;
    EXPECT_TRUE(bitwise_equal(direct, phased_async)) << where;
    // The same values cross the faces; only the edges and corners (which now ride in the
    // face messages) leave the direct form's count of values.
    EXPECT_LE(phased_x.messages_sent(), 6);
    EXPECT_LE(phased_x.messages_sent(), direct_x.messages_sent());
    EXPECT_EQ(phased_x.rounds(), 3);
    EXPECT_EQ(direct_x.rounds(), 1);
  });
}

TEST(HaloExchange, SingleRankCopiesLocallyWithoutMessages) {
  int p = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &p);
  CartDecomposition dec(MPI_COMM_WORLD, {8 * p, 8, 8}, 3, {p, 1, 1});
  Field a(dec, {"a", Stagger::cell, 3, WallParity::even});
  HaloExchange x(dec, {&a});
  if (p == 1) {
    EXPECT_EQ(x.messages_sent(), 0);
    EXPECT_EQ(x.bytes_sent_mpi(), 0u);
  } else {
    EXPECT_GT(x.messages_sent(), 0);
  }
  // 8^3 block, halo 3, walls in y, so only the 8 directions with no y step carry data:
  // x faces 3*8*8, z faces 8*8*3, xz edges 3*8*3 values each.  pz = 1 makes the z faces
  // (and, when px = 1 too, everything) a copy to itself.
  const std::size_t z_faces = 2 * 192, all = 2 * 192 + 2 * 192 + 4 * 72;
  EXPECT_EQ(x.bytes_copied_local(), (p == 1 ? all : z_faces) * sizeof(double));
  EXPECT_EQ(x.bytes_sent_mpi(), (p == 1 ? 0 : all - z_faces) * sizeof(double));
}

TEST(HaloExchange, MessageCountMatchesNeighbourDirections) {
  int p = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &p);
  if (p != 8) GTEST_SKIP() << "needs 8 ranks as 2x2x2";
  CartDecomposition dec(MPI_COMM_WORLD, {8, 8, 8}, 3, {2, 2, 2});
  Field a(dec, {"a", Stagger::cell, 1, WallParity::even});
  HaloExchange full(dec, {&a}, Reach::full), faces(dec, {&a}, Reach::faces), phased(dec, {&a}, Reach::full_phased);
  // One y side is a wall: 26 - 9 directions cross it, 17 remain; faces: 6 - 1 = 5.
  EXPECT_EQ(full.messages_sent(), 17);
  EXPECT_EQ(faces.messages_sent(), 5);
  EXPECT_EQ(phased.messages_sent(), 5);
  // 4^3 cells a rank, halo 1, a wall below or above: x faces 4x4, y face 6x4 (x ghosts ride
  // along), z faces 6x5 (x and the one y neighbour's ghosts).
  EXPECT_EQ(phased.bytes_sent_mpi(), (2 * 16 + 24 + 2 * 30) * sizeof(double));
  // 5 faces, 4 xz edges, 2 xy and 2 yz edges, 4 corners: the same 116 values.
  EXPECT_EQ(full.bytes_sent_mpi(), (5 * 16 + 4 * 4 + 2 * 4 + 2 * 4 + 4 * 1) * sizeof(double));
}

bool wall_face_row(const Field& f, int j) {
  const int gj = f.offset()[Y] + j;
  return is_staggered(f.stagger(), Y) && f.spec().parity == WallParity::odd && (gj == 0 || gj == kGlobal[Y]);
}

// An exchange that leaves an axis out fills the other axes' face ghosts as the whole one
// does and does not touch a ghost beyond the left-out axis's faces (nor, for y, the walls),
// but for the wall face rows the wall rule zeroes whole.
TEST(HaloExchange, LeftOutAxisKeepsItsGhostsAndFillsTheOthers) {
  for_each_decomposition([](const CartDecomposition& dec, const std::vector<FieldSpec>& specs,
                            const std::string& label) {
    for (int left_out = 0; left_out < 3; ++left_out) {
      const std::string where = label + " axis " + std::to_string(left_out);
      std::array<bool, 3> axes{true, true, true};
      axes[left_out] = false;
      for (CommMode mode : {CommMode::sync, CommMode::async}) {
        FieldSet whole(dec, specs), part(dec, specs);
        HaloExchange whole_x(dec, whole.ptrs, Reach::faces);
        HaloExchange part_x(dec, part.ptrs, Reach::faces, nullptr, axes);
        whole_x.exchange();
        if (mode == CommMode::sync) {
          part_x.exchange();
        } else {
          part_x.begin();
          part_x.finish();
        }
        long long wrong = 0;
        for (std::size_t n = 0; n < part.ptrs.size(); ++n) {
          const Field &f = *part.ptrs[n], &ref = *whole.ptrs[n];
          const int h = f.halo();
          for (int k = -h; k < f.n()[Z] + h; ++k)
            for (int j = -h; j < f.n()[Y] + h; ++j)
              for (int i = -h; i < f.n()[X] + h; ++i) {
                const int idx[3] = {i, j, k};
                int outside = 0, axis = -1;
                for (int a = 0; a < 3; ++a)
                  if (!inside(f, a, idx[a])) ++outside, axis = a;
                if (outside > 1) continue;
                const double got = f(i, j, k);
                // Owned points and ghosts of the exchanged axes as the whole exchange; ghosts
                // of the left-out axis untouched (still unset, NaN).
                // With y left out, owned points and x and z ghosts are the periodic copies
                // of the values as set.
                const double as_set = formula(static_cast<int>(n), wrap(f.offset()[X] + i, kGlobal[X]),
                                              f.offset()[Y] + j, wrap(f.offset()[Z] + k, kGlobal[Z]));
                bool ok;
                if (outside == 0 || axis != left_out)
                  ok = got == (left_out == Y ? as_set : ref(i, j, k));
                else  // the wall rule zeroes an odd y-face field's wall face rows whole
                  ok = wall_face_row(f, j) ? got == 0.0 : std::isnan(got);
                if (!ok && wrong++ < 3)
                  ADD_FAILURE() << where << " field " << f.name() << " at local (" << i << "," << j << "," << k
                                << "): got " << got << ", whole exchange " << ref(i, j, k);
              }
        }
        EXPECT_EQ(wrong, 0) << where << (mode == CommMode::sync ? " sync" : " async");
      }
    }
  });
}

// finish_across(X) between begin() and finish() fills every ghost beyond the x faces (with
// y owned: the wall rows wait for finish()), and finish() then leaves the fields bitwise as a
// plain exchange does.
// Phased, the x round is the first: the x ghosts over the owned z planes are current; those
// beside the z ghosts ride the z round.
void check_finish_across_x(Reach reach) {
  for_each_decomposition([reach](const CartDecomposition& dec, const std::vector<FieldSpec>& specs,
                                 const std::string& where) {
    FieldSet early(dec, specs), plain(dec, specs);
    HaloExchange early_x(dec, early.ptrs, reach), plain_x(dec, plain.ptrs, reach);
    plain_x.exchange();
    early_x.begin();
    early_x.finish_across(X);
    long long wrong = 0;
    for (std::size_t n = 0; n < early.ptrs.size(); ++n) {
      const Field& f = *early.ptrs[n];
      const int h = f.halo();
      const int klo = reach == Reach::full ? -h : 0, khi = reach == Reach::full ? f.n()[Z] + h : f.owned_end(Z);
      for (int k = klo; k < khi; ++k)
        for (int j = 0; j < f.owned_end(Y); ++j)
          for (int i = -h; i < f.n()[X] + h; ++i) {
            if (inside(f, X, i) || wall_face_row(f, j)) continue;
            const double want = expected(f, static_cast<int>(n), f.offset()[X] + i, f.offset()[Y] + j, f.offset()[Z] + k);
            if (!(f(i, j, k) == want) && wrong++ < 3)
              ADD_FAILURE() << where << " field " << f.name() << " at local (" << i << "," << j << "," << k
                            << "): got " << f(i, j, k) << ", want " << want;
          }
    }
    EXPECT_EQ(wrong, 0) << where;
    early_x.finish();
    EXPECT_EQ(count_wrong(early, reach, where), 0);
    EXPECT_TRUE(bitwise_equal(early, plain)) << where;
  });
}

TEST(HaloExchange, FinishAcrossXFillsTheXGhostsFirst) { check_finish_across_x(Reach::full); }

TEST(HaloExchange, PhasedFinishAcrossXFillsTheXFaceGhostsFirst) { check_finish_across_x(Reach::full_phased); }
