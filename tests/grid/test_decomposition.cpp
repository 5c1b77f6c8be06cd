// The Cartesian decomposition: choice of PX x PY x PZ, local blocks, neighbours, fields copied across halos, and
// clear errors (on every rank, without hanging) for set-ups that cannot work.
#include <gtest/gtest.h>
#include <mpi.h>

#include <string>

#include "config_error.hpp"
#include "decomposition.hpp"
#include "field.hpp"
#include "mpi_test_support.hpp"

using efsi::CartDecomposition;
using efsi::ConfigError;
using efsi::Field;
using efsi::Stagger;
using efsi::WallParity;
using efsi::X;
using efsi::Y;
using efsi::Z;
using efsi::Int3;

using efsi::testing::config_error_of;
using efsi::testing::world_size;

TEST(ChooseDims, HaloCostCountsFacesWallsAndTheXWeight) {
  // 64^3 blocks: a face is 4096 cells.
  EXPECT_DOUBLE_EQ(efsi::halo_cost({1, 1, 1}, {64, 64, 64}), 0.0);
  EXPECT_DOUBLE_EQ(efsi::halo_cost({1, 1, 2}, {64, 64, 64}), 2 * 4096.0);
  EXPECT_DOUBLE_EQ(efsi::halo_cost({1, 2, 1}, {64, 64, 64}), 4096.0);  // each rank has a wall
  EXPECT_DOUBLE_EQ(efsi::halo_cost({1, 4, 1}, {64, 64, 64}), 1.5 * 4096.0);
  EXPECT_DOUBLE_EQ(efsi::halo_cost({2, 1, 1}, {64, 64, 64}), 2 * efsi::kXFaceWeight * 4096.0);
  EXPECT_DOUBLE_EQ(efsi::halo_cost({2, 1, 2}, {32, 16, 8}), 2 * efsi::kXFaceWeight * 16 * 8 + 2.0 * 32 * 16);
}

TEST(ChooseDims, CheapestPermutationOfTheBalancedFactors) {
  // A cube: y first (walls), then z; x is cut last.
  EXPECT_EQ(efsi::choose_dims(2, {64, 64, 64}, 3), (Int3{1, 2, 1}));
  EXPECT_EQ(efsi::choose_dims(4, {64, 64, 64}, 3), (Int3{1, 2, 2}));
  EXPECT_EQ(efsi::choose_dims(8, {64, 64, 64}, 3), (Int3{2, 2, 2}));
  EXPECT_EQ(efsi::choose_dims(12, {48, 48, 48}, 3), (Int3{2, 3, 2}));
  EXPECT_EQ(efsi::choose_dims(2, {64, 64, 64}, 3, {0, 1, 0}), (Int3{1, 1, 2}));
  // The paper's strong-scaling box is long in x: a cut there has half the face cells, yet
  // costs more than one in y.
  EXPECT_EQ(efsi::choose_dims(2, {2048, 1024, 1024}, 3), (Int3{1, 2, 1}));
  // A box long enough in x that its short x faces win.
  EXPECT_EQ(efsi::choose_dims(2, {1024, 64, 64}, 3), (Int3{2, 1, 1}));
  // Weak scaling: the block is fixed and the box follows the grid.
  EXPECT_EQ(efsi::choose_block_dims(1, {64, 64, 64}), (Int3{1, 1, 1}));
  EXPECT_EQ(efsi::choose_block_dims(2, {64, 64, 64}), (Int3{1, 2, 1}));
  EXPECT_EQ(efsi::choose_block_dims(4, {64, 64, 64}), (Int3{1, 2, 2}));
  EXPECT_EQ(efsi::choose_block_dims(8, {64, 64, 64}), (Int3{2, 2, 2}));
}

TEST(ChooseDims, DividesTheGridWithTheBalancedFactors) {
  EXPECT_EQ(efsi::choose_dims(1, {10, 12, 14}, 3), (Int3{1, 1, 1}));
  // The paper's strong-scaling grid on 8192 ranks: 64^3 cells per rank.
  const Int3 d = efsi::choose_dims(8192, {2048, 1024, 1024}, 3);
  EXPECT_EQ(efsi::product(d), 8192);
  EXPECT_EQ(2048LL / d[0] * (1024 / d[1]) * (1024 / d[2]), 2048LL * 1024 * 1024 / 8192);
}

TEST(ChooseDims, FallsBackToADividingFactorisation) {
  // MPI_Dims_create(6) gives 3x2x1, but 3 divides only nz here.
  const Int3 d = efsi::choose_dims(6, {16, 16, 48}, 3);
  EXPECT_EQ(efsi::product(d), 6);
  for (int a = 0; a < 3; ++a) EXPECT_EQ((Int3{16, 16, 48})[a] % d[a], 0) << "axis " << a;
  EXPECT_EQ(d[2] % 3, 0);
}

TEST(ChooseDims, KeepsForcedEntries) {
  EXPECT_EQ(efsi::choose_dims(8, {64, 64, 64}, 3, {8, 1, 1}), (Int3{8, 1, 1}));
  EXPECT_EQ(efsi::choose_dims(8, {64, 64, 64}, 3, {0, 1, 0})[1], 1);
}

TEST(ChooseDims, RejectsForcedProductMismatch) {
  const std::string m = config_error_of([] { efsi::choose_dims(4, {64, 64, 64}, 3, {3, 1, 1}); });
  EXPECT_NE(m.find("3x1x1"), std::string::npos) << m;
  EXPECT_NE(m.find("needs 3 ranks but 4"), std::string::npos) << m;
}

TEST(ChooseDims, RejectsForcedNonDividing) {
  const std::string m = config_error_of([] { efsi::choose_dims(3, {64, 64, 64}, 3, {3, 1, 1}); });
  EXPECT_NE(m.find("Nx=64 is not a multiple of Px=3"), std::string::npos) << m;
}

TEST(ChooseDims, RejectsBlockThinnerThanHalo) {
  const std::string m = config_error_of([] { efsi::choose_dims(8, {16, 16, 16}, 3, {8, 1, 1}); });
  EXPECT_NE(m.find("local block is 2 cells in x"), std::string::npos) << m;
  EXPECT_NE(m.find("halo width 3"), std::string::npos) << m;
}

TEST(ChooseDims, RejectsWhenNothingFits) {
  // 7 ranks, no axis a multiple of 7.
  const std::string m = config_error_of([] { efsi::choose_dims(7, {16, 16, 16}, 3); });
  EXPECT_NE(m.find("no decomposition of 7 ranks fits grid 16x16x16"), std::string::npos) << m;
}

TEST(CartDecomposition, BlocksTileTheGridAndNeighboursWrap) {
  const int p = world_size();
  const Int3 global{12 * p, 24, 12};
  CartDecomposition dec(MPI_COMM_WORLD, global, 3, {p, 1, 1});
  EXPECT_EQ(dec.local(), (Int3{12, 24, 12}));
  EXPECT_EQ(dec.offset()[0], 12 * dec.coords()[0]);
  EXPECT_TRUE(dec.wall_below());
  EXPECT_TRUE(dec.wall_above());
  EXPECT_EQ(dec.neighbour({0, 1, 0}), MPI_PROC_NULL);
  EXPECT_EQ(dec.neighbour({0, -1, 0}), MPI_PROC_NULL);
  EXPECT_EQ(dec.neighbour({0, 0, 1}), dec.rank());  // pz = 1: its own neighbour
  Int3 c = dec.coords();
  c[0] = (c[0] + 1) % p;
  EXPECT_EQ(dec.neighbour({1, 0, 0}), c[0]);  // p x 1 x 1: the rank is its x coordinate

  // Sum of local volumes equals the global volume.
  long long v = efsi::product(dec.local()), total = 0;
  MPI_Allreduce(&v, &total, 1, MPI_LONG_LONG, MPI_SUM, dec.comm());
  EXPECT_EQ(total, efsi::product(global));
}

// The grid is computed by hand (no MPI_Cart_create, which SimGrid's SMPI takes hours for at
// 8192 ranks): on every rank grid of this rank count it is MPI's own Cartesian topology,
// periodic in x and z, not reordered: the coordinates, the 26 neighbours, and the
// communicators of MPI_Cart_sub, same groups in the same order.
TEST(CartDecomposition, IsMpisCartesianTopologyOnEveryGrid) {
  const int p = world_size();
  for (int d0 = 1; d0 <= p; ++d0)
    for (int d1 = 1; d0 * d1 <= p; ++d1) {
      if (p % (d0 * d1) != 0) continue;
      const Int3 dims{d0, d1, p / (d0 * d1)};
      SCOPED_TRACE(efsi::to_string(dims));
      CartDecomposition dec(MPI_COMM_WORLD, {3 * dims[0], 3 * dims[1], 3 * dims[2]}, 3, dims);
      ASSERT_EQ(dec.dims(), dims);
      MPI_Comm cart;
      const int periodic[3] = {1, 0, 1};
      MPI_Cart_create(MPI_COMM_WORLD, 3, dims.data(), periodic, 0, &cart);
      Int3 coords{};
      MPI_Cart_coords(cart, dec.rank(), 3, coords.data());
      EXPECT_EQ(dec.coords(), coords);
      for (int sz = -1; sz <= 1; ++sz)
        for (int sy = -1; sy <= 1; ++sy)
          for (int sx = -1; sx <= 1; ++sx) {
            Int3 c{coords[0] + sx, coords[1] + sy, coords[2] + sz};
            int expected = MPI_PROC_NULL;
            if (c[1] >= 0 && c[1] < dims[1]) MPI_Cart_rank(cart, c.data(), &expected);
            EXPECT_EQ(dec.neighbour({sx, sy, sz}), expected) << sx << "," << sy << "," << sz;
          }
      for (int keep = 1; keep < 7; ++keep) {
        const std::array<bool, 3> kept{(keep & 1) != 0, (keep & 2) != 0, (keep & 4) != 0};
        const int remain[3] = {kept[0], kept[1], kept[2]};
        MPI_Comm mine = dec.sub_comm(kept), theirs;
        MPI_Cart_sub(cart, remain, &theirs);
        int same = MPI_UNEQUAL;
        MPI_Comm_compare(mine, theirs, &same);
        EXPECT_EQ(same, MPI_CONGRUENT) << "keep " << keep;
        MPI_Comm_free(&mine);
        MPI_Comm_free(&theirs);
      }
      MPI_Comm_free(&cart);
    }
}

TEST(CartDecomposition, WallsOnlyAtTheOuterRanksInY) {
  const int p = world_size();
  CartDecomposition dec(MPI_COMM_WORLD, {6, 6 * p, 6}, 3, {1, p, 1});
  EXPECT_EQ(dec.wall_below(), dec.coords()[1] == 0);
  EXPECT_EQ(dec.wall_above(), dec.coords()[1] == p - 1);
  EXPECT_EQ(dec.neighbour({0, -1, 0}) == MPI_PROC_NULL, dec.wall_below());
  EXPECT_EQ(dec.neighbour({0, 1, 0}) == MPI_PROC_NULL, dec.wall_above());
}

// Every rank must throw the same error before any collective call; the barrier after it
// would hang (and the CTest timeout fail the test) if one rank went on.
TEST(CartDecomposition, BadSetUpThrowsOnEveryRankWithoutHanging) {
  const int p = world_size();
  const std::string bad_product =
      config_error_of([&] { CartDecomposition d(MPI_COMM_WORLD, {64, 64, 64}, 3, {p + 1, 1, 1}); });
  EXPECT_NE(bad_product.find("needs " + std::to_string(p + 1) + " ranks"), std::string::npos) << bad_product;

  const std::string thin = config_error_of([&] { CartDecomposition d(MPI_COMM_WORLD, {2 * p, 6, 6}, 3, {p, 1, 1}); });
  EXPECT_NE(thin.find("thinner than the halo width 3"), std::string::npos) << thin;

  if (p > 1) {
    const std::string indivisible =
        config_error_of([&] { CartDecomposition d(MPI_COMM_WORLD, {64 * p + 1, 64, 64}, 3, {p, 1, 1}); });
    EXPECT_NE(indivisible.find("is not a multiple of Px=" + std::to_string(p)), std::string::npos) << indivisible;
  }
  MPI_Barrier(MPI_COMM_WORLD);
}

// The owned points cross between fields of different halos; the ghosts stay; another
// extent or stagger is refused.
TEST(Field, CopyOwnedFromAFieldOfAnotherHalo) {
  CartDecomposition dec(MPI_COMM_WORLD, {24, 24, 24}, 3);
  Field shallow(dec, {"shallow", Stagger::cell, 1, WallParity::even});
  Field deep(dec, {"deep", Stagger::cell, 3, WallParity::even});
  const Int3 n = dec.local();
  shallow.fill(-1.0);
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) shallow(i, j, k) = i + 10.0 * j + 100.0 * k;
  deep.fill(7.0);
  deep.copy_owned_from(shallow);
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) EXPECT_EQ(deep(i, j, k), i + 10.0 * j + 100.0 * k);
  EXPECT_EQ(deep(-1, 0, 0), 7.0);
  EXPECT_EQ(deep(0, 0, n[Z] + 2), 7.0);
  Field face(dec, {"face", Stagger::face_x, 1, WallParity::odd});
  EXPECT_THROW(face.copy_owned_from(shallow), ConfigError);
}
