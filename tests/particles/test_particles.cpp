// Particles (docs/numerics.md, "Particles") and the centroid diagnostic (section 6): the paper's
// particle counts, orientations that depend on the site alone, placement checks that
// pass for the paper's set-up and fail with the numbers for overrides, a solid fraction
// with the Evans-Fung volume that is bitwise the same on every decomposition, and
// connected regions whose centroids sit on the particle centres, across ranks and across
// the periodic seams.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "centroids.hpp"
#include "config_error.hpp"
#include "decomposition.hpp"
#include "domain.hpp"
#include "field.hpp"
#include "mpi_test_support.hpp"
#include "particles.hpp"
#include "runtime.hpp"

using namespace efsi;
using namespace efsi::testing;

namespace {

// Relative error of <phi> * box volume against the Evans-Fung volume, with 4^3 samples a
// cell at 64 cells per 3.6: measured -2.9e-4 (2 particles) and -6.1e-5 (16); a single
// particle at 30 random places and orientations stays under 3.1e-4 (6.9e-4 at 32 cells).
constexpr double kVolumeTolerance = 1e-3;
// Centroid of a region against its particle's centre, in cells, at 32 cells per 3.6:
// 30 random places and orientations gave at most 0.067 (rms 0.029; at 64 cells, 0.024).
constexpr double kCentroidTolerance = 0.1;

// The paper's boxes at `per_cell` grid cells per 3.6.
Domain box(double lx, double ly, double lz, int per_cell) {
  Domain d;
  d.length = {lx, ly, lz};
  for (int a = 0; a < 3; ++a) d.cells[a] = static_cast<int>(std::lround(d.length[a] / 3.6 * per_cell));
  return d;
}

// Every PX x PY x PZ of the started ranks that splits the grid into blocks of at least
// 3 cells (phi's halo width), as a driver might be forced to use.
std::vector<Int3> decompositions(const Int3& cells) { return fitting_decompositions(world_size(), cells, 3); }

Field make_phi(const CartDecomposition& dec) { return Field(dec, {"phi", Stagger::cell, 3, WallParity::even}); }

std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Fingerprint of the owned cells that no reduction order can change: the sum modulo 2^64
// of a hash of (global cell index, bit pattern of phi).  Any changed bit in any cell
// changes it (up to hash collisions).
std::uint64_t fingerprint(const Field& phi, const Int3& global, MPI_Comm comm) {
  std::uint64_t h = 0;
  for (int k = 0; k < phi.n()[Z]; ++k)
    for (int j = 0; j < phi.n()[Y]; ++j)
      for (int i = 0; i < phi.n()[X]; ++i) {
        const std::int64_t gi = phi.offset()[X] + i, gj = phi.offset()[Y] + j, gk = phi.offset()[Z] + k;
        const auto g = static_cast<std::uint64_t>(gi + global[X] * (gj + global[Y] * gk));
        std::uint64_t bits = 0;
        const double v = phi(i, j, k);
        std::memcpy(&bits, &v, sizeof bits);
        h += mix64(g * 0x9E3779B97F4A7C15ull ^ mix64(bits));
      }
  std::uint64_t total = 0;
  MPI_Allreduce(&h, &total, 1, MPI_UINT64_T, MPI_SUM, comm);
  return total;
}

double owned_sum(const Field& phi, MPI_Comm comm) {
  double s = 0;
  for (int k = 0; k < phi.n()[Z]; ++k)
    for (int j = 0; j < phi.n()[Y]; ++j)
      for (int i = 0; i < phi.n()[X]; ++i) s += phi(i, j, k);
  double total = 0;
  MPI_Allreduce(&s, &total, 1, MPI_DOUBLE, MPI_SUM, comm);
  return total;
}

double nearest_image(double d, double l) { return d - l * std::round(d / l); }

// Distance in cells between a centroid and a centre, nearest image in x and z.
double cells_apart(const std::array<double, 3>& a, const std::array<double, 3>& b, const Domain& dom) {
  double s = 0;
  for (int ax = 0; ax < 3; ++ax) {
    double d = a[ax] - b[ax];
    if (ax != Y) d = nearest_image(d, dom.length[ax]);
    d /= dom.spacing(ax);
    s += d * d;
  }
  return std::sqrt(s);
}

// Regions computed by rank 0 alone on the whole grid, sent to every rank: the reference
// every decomposition must reproduce.
std::vector<SolidRegion> serial_regions(const Domain& dom, const std::vector<Particle>& ps, const ParticleSpec& spec,
                                        std::uint64_t* fp) {
  std::vector<double> flat;
  std::uint64_t f = 0;
  if (world_rank() == 0) {
    // One thread too, so that a threaded run also compares against unthreaded filling.
    const int threads = max_threads();
    set_threads(1);
    CartDecomposition one(MPI_COMM_SELF, dom.cells, 3);
    Field phi = make_phi(one);
    fill_solid_fraction(phi, dom, ps, spec);
    f = fingerprint(phi, dom.cells, MPI_COMM_SELF);
    for (const SolidRegion& r : solid_regions(phi, dom, one))
      flat.insert(flat.end(), {r.volume, r.centroid[0], r.centroid[1], r.centroid[2], double(r.cells),
                               double(r.first_cell), double(r.wraps[0] + 2 * r.wraps[1] + 4 * r.wraps[2])});
    set_threads(threads);
  }
  MPI_Bcast(&f, 1, MPI_UINT64_T, 0, MPI_COMM_WORLD);
  long long n = static_cast<long long>(flat.size());
  MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  flat.resize(static_cast<std::size_t>(n));
  MPI_Bcast(flat.data(), static_cast<int>(n), MPI_DOUBLE, 0, MPI_COMM_WORLD);
  std::vector<SolidRegion> out;
  for (std::size_t m = 0; m + 7 <= flat.size(); m += 7) {
    const int w = static_cast<int>(flat[m + 6]);
    out.push_back({flat[m], {flat[m + 1], flat[m + 2], flat[m + 3]}, static_cast<std::int64_t>(flat[m + 4]),
                   static_cast<std::int64_t>(flat[m + 5]), {(w & 1) != 0, (w & 2) != 0, (w & 4) != 0}});
  }
  if (fp) *fp = f;
  return out;
}

void expect_same_regions(const std::vector<SolidRegion>& got, const std::vector<SolidRegion>& want,
                         const std::string& where) {
  ASSERT_EQ(got.size(), want.size()) << where;
  for (std::size_t m = 0; m < got.size(); ++m) {
    EXPECT_EQ(got[m].first_cell, want[m].first_cell) << where << " region " << m;
    EXPECT_EQ(got[m].cells, want[m].cells) << where << " region " << m;
    EXPECT_EQ(got[m].wraps, want[m].wraps) << where << " region " << m;
    EXPECT_NEAR(got[m].volume, want[m].volume, 1e-12 * want[m].volume) << where << " region " << m;
    for (int ax = 0; ax < 3; ++ax) EXPECT_NEAR(got[m].centroid[ax], want[m].centroid[ax], 1e-10) << where;
  }
}

// Fills phi on every decomposition of the started ranks and compares its regions with the
// serial reference.
void expect_same_regions_on_every_decomposition(const Domain& dom, const std::vector<Particle>& ps,
                                                const ParticleSpec& spec, const std::vector<SolidRegion>& reference) {
  for (const Int3& dims : decompositions(dom.cells)) {
    CartDecomposition dec(MPI_COMM_WORLD, dom.cells, 3, dims);
    Field phi = make_phi(dec);
    fill_solid_fraction(phi, dom, ps, spec);
    expect_same_regions(solid_regions(phi, dom, dec), reference, "decomposition " + to_string(dims));
  }
}

}  // namespace

TEST(EvansFung, ClosedFormVolumeMatchesQuadrature) {
  // V = 2 * int_0^R 2 pi r h(r) dr (two halves) = 2 pi R^3 int_0^1 rho sqrt(1-rho^2) P(rho^2) d rho.
  // rho = sin(theta) removes the square-root end point, so Simpson converges fast.
  const auto f = [](double th) {
    const double s = std::sin(th), c = std::cos(th), t = s * s;
    return s * c * c * (kEvansFungC0 + kEvansFungC1 * t + kEvansFungC2 * t * t);
  };
  const int m = 2000;
  const double a = 0.0, b = std::numbers::pi / 2, h = (b - a) / m;
  double sum = f(a) + f(b);
  for (int q = 1; q < m; ++q) sum += (q % 2 ? 4.0 : 2.0) * f(a + q * h);
  const double integral = sum * h / 3.0;
  for (double d : {2.0, 1.0, 3.7}) {
    const double r = d / 2;
    EXPECT_NEAR(evans_fung_volume(d), 2 * std::numbers::pi * r * r * r * integral, 1e-12 * r * r * r) << d;
  }
  EXPECT_NEAR(evans_fung_volume(2.0), 1.574049, 1e-6);

  // The thickest point, found by brute force, bounds the half-thickness everywhere.
  double hmax = 0;
  for (int q = 0; q <= 1000000; ++q) hmax = std::max(hmax, evans_fung_half_thickness(q / 1e6, 1.0));
  EXPECT_NEAR(evans_fung_max_half_thickness(1.0), hmax, 1e-9);
  EXPECT_GE(evans_fung_max_half_thickness(1.0), hmax);
  EXPECT_DOUBLE_EQ(evans_fung_half_thickness(0.0, 1.0), kEvansFungC0 / 2);
  EXPECT_EQ(evans_fung_half_thickness(1.0, 1.0), 0.0);
}

TEST(Particles, InsideFollowsTheProfileAndWrapsInXAndZ) {
  const Domain dom = box(3.6, 3.6, 3.6, 64);
  const ParticleSpec spec;
  const Particle p{0, {0.1, 1.8, 3.5}, {0.0, 1.0, 0.0}};
  const double h_mid = evans_fung_half_thickness(0.5, 1.0);
  // Half a radius out along x, so the point lies across the x seam (x = 0.1 - 0.5 + 3.6).
  EXPECT_TRUE(inside_particle(p, spec, {3.2, 1.8 + 0.99 * h_mid, 3.5}, dom));
  EXPECT_FALSE(inside_particle(p, spec, {3.2, 1.8 + 1.01 * h_mid, 3.5}, dom));
  // Across the z seam, and across both at once.
  EXPECT_TRUE(inside_particle(p, spec, {0.1, 1.8, 0.2}, dom));
  EXPECT_TRUE(inside_particle(p, spec, {3.5, 1.8, 0.1}, dom));
  EXPECT_FALSE(inside_particle(p, spec, {0.1, 1.8, 3.5 - 1.01}, dom));
  // The extent bounds the solid and is reached: the highest solid point of a tilted disc
  // on a fine grid lies within a grid step of it.
  const double norm = std::sqrt(0.5 * 0.5 + 1.0 + 0.3 * 0.3);
  const Particle tilted{2, {1.8, 1.8, 1.8}, {0.5 / norm, 1.0 / norm, 0.3 / norm}};
  for (int ax = 0; ax < 3; ++ax) {
    const int m = 100;
    double top = -1;
    for (int k = 0; k < m; ++k)
      for (int j = 0; j < m; ++j)
        for (int i = 0; i < m; ++i) {
          const std::array<double, 3> d{-1 + (i + 0.5) * 2 / m, -1 + (j + 0.5) * 2 / m, -1 + (k + 0.5) * 2 / m};
          if (inside_particle(tilted, spec, {1.8 + d[0], 1.8 + d[1], 1.8 + d[2]}, dom)) top = std::max(top, d[ax]);
        }
    const double e = particle_extent(tilted, spec, ax);
    EXPECT_LE(top, e) << "axis " << ax;
    EXPECT_GT(top, e - 2.0 / m * std::sqrt(3.0)) << "axis " << ax;
  }
  // No wrap across the walls: a particle at the bottom is not seen from the top.
  const Particle low{1, {1.8, 0.1, 1.8}, {0.0, 1.0, 0.0}};
  EXPECT_TRUE(inside_particle(low, spec, {1.8, 0.15, 1.8}, dom));
  EXPECT_FALSE(inside_particle(low, spec, {1.8, 3.55, 1.8}, dom));
}

TEST(Lattice, PaperParticleCounts) {
  EXPECT_EQ(lattice_site_count(box(3.6, 3.6, 3.6, 64)), 2);
  EXPECT_EQ(lattice_site_count(box(7.2, 7.2, 7.2, 64)), 16);
  EXPECT_EQ(lattice_site_count(box(115.2, 57.6, 57.6, 64)), 16384);
  EXPECT_EQ(lattice_particles(box(3.6, 3.6, 3.6, 64), -1).size(), 2u);
  EXPECT_EQ(lattice_particles(box(7.2, 7.2, 7.2, 64), -1).size(), 16u);
  const auto strong = lattice_particles(box(115.2, 57.6, 57.6, 64), -1);
  ASSERT_EQ(strong.size(), 16384u);
  EXPECT_EQ(strong.back().index, 16383);
  EXPECT_EQ(lattice_particles(box(7.2, 7.2, 7.2, 64), 5).size(), 5u);
  EXPECT_TRUE(lattice_particles(box(5.0, 1.0, 2.0, 64), 0).empty());  // no particles: any box
}

TEST(Lattice, SitesAndOrientations) {
  const Domain dom = box(7.2, 7.2, 7.2, 64);
  const ParticleSpec spec;
  const auto all = lattice_particles(dom, -1, spec);
  // Body-centred cubic, cell x fastest, the two sites of a cell consecutive.
  const std::array<double, 3> want[] = {{0.9, 0.9, 0.9}, {2.7, 2.7, 2.7}, {4.5, 0.9, 0.9}, {6.3, 2.7, 2.7},
                                        {0.9, 4.5, 0.9}};
  for (int s = 0; s < 5; ++s)
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(all[s].centre[a], want[s][a], 1e-12) << "site " << s;
  EXPECT_NEAR(all[15].centre[Z], 6.3, 1e-12);

  // The orientation of site i is the same however many particles were asked for, and in
  // any domain: it comes from (seed, i) alone.
  const auto few = lattice_particles(dom, 5, spec);
  const auto strong = lattice_particles(box(115.2, 57.6, 57.6, 64), -1, spec);
  for (int s = 0; s < 5; ++s) {
    EXPECT_EQ(std::memcmp(few[s].axis.data(), all[s].axis.data(), sizeof few[s].axis), 0) << s;
    EXPECT_EQ(std::memcmp(strong[s].axis.data(), all[s].axis.data(), sizeof few[s].axis), 0) << s;
  }
  double max_tilt = 0, min_tilt = 90;
  for (const Particle& p : strong) {
    const auto& n = p.axis;
    EXPECT_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1.0, 1e-14);
    const double tilt = std::acos(std::min(1.0, n[Y])) * 180 / std::numbers::pi;
    max_tilt = std::max(max_tilt, tilt);
    min_tilt = std::min(min_tilt, tilt);
  }
  EXPECT_LE(max_tilt, 30.0 + 1e-9);
  EXPECT_GT(max_tilt, 29.9);  // 16384 draws fill the cap
  EXPECT_LT(min_tilt, 1.0);

  ParticleSpec other = spec;
  other.seed = 54321;
  EXPECT_NE(particle_axis(3, other), particle_axis(3, spec));
  other.seed = spec.seed;
  other.max_tilt_deg = 0;
  EXPECT_EQ(particle_axis(3, other), (std::array<double, 3>{0.0, 1.0, 0.0}));
}

TEST(Lattice, ConfigErrorsNameTheNumbers) {
  const std::string too_many = config_error_of([] { lattice_particles(box(3.6, 3.6, 3.6, 64), 3); });
  EXPECT_NE(too_many.find("requested 3 particles"), std::string::npos) << too_many;
  EXPECT_NE(too_many.find("only 2 lattice sites"), std::string::npos) << too_many;
  EXPECT_NE(too_many.find("3.6 x 3.6 x 3.6"), std::string::npos) << too_many;

  Domain odd = box(3.6, 3.6, 3.6, 64);
  odd.length[Y] = 5.0;
  const std::string not_whole = config_error_of([&] { lattice_particles(odd, 2); });
  EXPECT_NE(not_whole.find("Ly = 5 "), std::string::npos) << not_whole;
  EXPECT_NE(not_whole.find("3.6"), std::string::npos) << not_whole;
  EXPECT_NE(not_whole.find("1.38889"), std::string::npos) << not_whole;
  EXPECT_EQ(not_whole.find('\n'), std::string::npos);

  ParticleSpec bad;
  bad.max_tilt_deg = 120;
  EXPECT_NE(config_error_of([&] { lattice_particles(box(3.6, 3.6, 3.6, 64), 2, bad); }).find("120"),
            std::string::npos);
}

TEST(CheckParticles, PaperPlacementsPass) {
  // D = 2.0 at dx = 0.05625 (64 cells per 3.6).  Nearest sites are sqrt(3)/2 * 3.6 = 3.12
  // apart, more than D: no two bounding spheres meet, whatever the orientations.
  EXPECT_GT(std::sqrt(3.0) / 2 * 3.6, ParticleSpec{}.diameter);
  EXPECT_NO_THROW(check_particles(box(3.6, 3.6, 3.6, 64), lattice_particles(box(3.6, 3.6, 3.6, 64), -1)));
  EXPECT_NO_THROW(check_particles(box(7.2, 7.2, 7.2, 64), lattice_particles(box(7.2, 7.2, 7.2, 64), -1)));
  const Domain strong = box(115.2, 57.6, 57.6, 64);
  const auto all = lattice_particles(strong, -1);
  EXPECT_NO_THROW(check_particles(strong, all));

  // The walls too, for any draw: the worst case is the largest tilt at the lowest site.
  const double tilt = 30.0 * std::numbers::pi / 180;
  const Particle worst{0, {0.9, 0.9, 0.9}, {std::sin(tilt), std::cos(tilt), 0.0}};
  const double gap = 0.9 - particle_extent(worst, {}, Y);
  EXPECT_GT(gap, 2 * strong.spacing(Y));
  EXPECT_NO_THROW(check_particles(box(3.6, 3.6, 3.6, 64), {worst}));
  double nearest = 1e9;
  for (const Particle& p : all) nearest = std::min(nearest, p.centre[Y] - particle_extent(p, {}, Y));
  if (world_rank() == 0)
    std::printf("[ particles ] wall gap: worst case %.4f, smallest of the 16384 %.4f, limit %.4f\n", gap, nearest,
                2 * strong.spacing(Y));
}

TEST(CheckParticles, DiameterOverridesFailWithTheNumbers) {
  const Domain dom = box(7.2, 7.2, 7.2, 64);  // dx = 0.05625, wall limit 2 dx = 0.1125
  ParticleSpec wide;
  // D = 3.0: spheres still apart (3.0 < 3.12) but a disc tilted by more than about 17
  // degrees reaches within 0.1125 of the wall from y = 0.9.
  wide.diameter = 3.0;
  const std::string wall = config_error_of([&] { check_particles(dom, lattice_particles(dom, -1, wide), wide); });
  EXPECT_NE(wall.find("from the wall y = "), std::string::npos) << wall;
  EXPECT_NE(wall.find("2 cells = 0.1125"), std::string::npos) << wall;
  EXPECT_NE(wall.find("diameter 3"), std::string::npos) << wall;

  // D = 3.8, flat discs: 0.28 from the walls is fine, but neighbours in x are 3.6 apart.
  ParticleSpec flat;
  flat.diameter = 3.8;
  flat.max_tilt_deg = 0;
  const std::string overlap = config_error_of([&] { check_particles(dom, lattice_particles(dom, -1, flat), flat); });
  EXPECT_NE(overlap.find("particles 0 and 2 overlap"), std::string::npos) << overlap;
  EXPECT_NE(overlap.find("centres 3.6 apart"), std::string::npos) << overlap;
  EXPECT_NE(overlap.find("diameter 3.8"), std::string::npos) << overlap;
  // The same with the paper's tilts: overlap is reported before the walls.
  wide.diameter = 4.0;
  const std::string both = config_error_of([&] { check_particles(dom, lattice_particles(dom, -1, wide), wide); });
  EXPECT_NE(both.find("overlap"), std::string::npos) << both;

  // In a single 3.6 cell a 3.8 disc meets its own periodic image.
  const Domain small = box(3.6, 3.6, 3.6, 64);
  const std::string self = config_error_of([&] { check_particles(small, lattice_particles(small, -1, flat), flat); });
  EXPECT_NE(self.find("own periodic image"), std::string::npos) << self;
  EXPECT_NE(self.find("Lx = 3.6"), std::string::npos) << self;
}

TEST(CheckParticles, HandPlacedPairsAndWalls) {
  const Domain dom = box(7.2, 7.2, 7.2, 64);
  const ParticleSpec spec;
  const std::array<double, 3> up{0.0, 1.0, 0.0};
  // Rims 1.9 apart across, 0.4 apart in height: the spheres and the bounding boxes meet
  // and no separating axis exists, so only sampling can tell; the rims (at most 0.17
  // half-thick there) do not touch.
  EXPECT_NO_THROW(check_particles(dom, {{0, {3.0, 3.0, 3.0}, up}, {1, {4.9, 3.4, 3.0}, up}}));
  const std::string touch =
      config_error_of([&] { check_particles(dom, {{0, {3.0, 3.0, 3.0}, up}, {1, {4.9, 3.2, 3.0}, up}}); });
  EXPECT_NE(touch.find("particles 0 and 1 overlap"), std::string::npos) << touch;
  // Stacked flat discs: 0.7 apart clear the thickest rings (2 x 0.328), 0.5 do not.
  EXPECT_NO_THROW(check_particles(dom, {{0, {3.0, 3.0, 3.0}, up}, {1, {3.0, 3.7, 3.0}, up}}));
  EXPECT_NE(config_error_of([&] { check_particles(dom, {{0, {3.0, 3.0, 3.0}, up}, {1, {3.0, 3.5, 3.0}, up}}); })
                .find("overlap"),
            std::string::npos);
  // Across the periodic seam: x = 0.2 and x = 7.0 are 0.4 apart.
  EXPECT_NE(config_error_of([&] { check_particles(dom, {{7, {0.2, 3.0, 3.0}, up}, {9, {7.0, 3.0, 3.0}, up}}); })
                .find("particles 7 and 9 overlap: centres 0.4 apart"),
            std::string::npos);

  // A flat disc reaches 0.328 below its centre: at y = 0.4 it is 0.072 from the wall.
  const std::string low = config_error_of([&] { check_particles(dom, {{4, {3.0, 0.4, 3.0}, up}}); });
  EXPECT_NE(low.find("particle 4 at y = 0.4 reaches 0.0719087 from the wall y = 0,"), std::string::npos) << low;
  const std::string high = config_error_of([&] { check_particles(dom, {{5, {3.0, 6.8, 3.0}, up}}); });
  EXPECT_NE(high.find("wall y = 7.2"), std::string::npos) << high;
  EXPECT_NO_THROW(check_particles(dom, {{4, {3.0, 0.45, 3.0}, up}}));

  const std::string skew = config_error_of([&] { check_particles(dom, {{3, {3.0, 3.0, 3.0}, {0.0, 2.0, 0.0}}}); });
  EXPECT_NE(skew.find("particle 3: axis (0, 2, 0) has length 2"), std::string::npos) << skew;
}

TEST(SolidFraction, VolumeMatchesEvansFung) {
  const ParticleSpec spec;
  struct Case {
    Domain dom;
    int particles;
  };
  for (const Case& c : {Case{box(3.6, 3.6, 3.6, 64), 2}, Case{box(7.2, 7.2, 7.2, 64), 16}}) {
    CartDecomposition dec(MPI_COMM_WORLD, c.dom.cells, 3);
    Field phi = make_phi(dec);
    const auto ps = lattice_particles(c.dom, -1, spec);
    ASSERT_EQ(static_cast<int>(ps.size()), c.particles);
    const double t0 = MPI_Wtime();
    fill_solid_fraction(phi, c.dom, ps, spec);
    const double seconds = MPI_Wtime() - t0;
    const double volume = owned_sum(phi, MPI_COMM_WORLD) * c.dom.cell_volume();
    const double exact = c.particles * evans_fung_volume(spec.diameter);
    const double err = (volume - exact) / exact;
    if (world_rank() == 0)
      std::printf("[ particles ] %s cells, %d particles: solid volume %.6f, exact %.6f, relative error %+.2e, "
                  "fill %.3f s\n",
                  to_string(c.dom.cells).c_str(), c.particles, volume, exact, err, seconds);
    EXPECT_LT(std::abs(err), kVolumeTolerance) << to_string(c.dom.cells);

    // Every value is a whole number of the 64 samples, in [0, 1].
    long long bad = 0;
    for (int k = 0; k < phi.n()[Z]; ++k)
      for (int j = 0; j < phi.n()[Y]; ++j)
        for (int i = 0; i < phi.n()[X]; ++i) {
          const double v = phi(i, j, k);
          bad += !(v >= 0.0 && v <= 1.0 && v * 64 == std::round(v * 64));
        }
    EXPECT_EQ(bad, 0);
  }
}

TEST(SolidFraction, BitwiseIdenticalOnEveryDecomposition) {
  // 32 cells per 3.6 keeps the serial reference small; particle 0 at x = 0.9 - 1 reaches
  // across the x seam on its own.
  const Domain dom = box(7.2, 7.2, 7.2, 32);
  const ParticleSpec spec;
  auto ps = lattice_particles(dom, -1, spec);
  // Across the z seam and overlapping a lattice particle on purpose: the clamp to 1 must
  // not depend on the decomposition either.
  ps.push_back({99, {3.6, 3.6, 7.15}, particle_axis(99, spec)});
  std::uint64_t reference = 0;
  serial_regions(dom, ps, spec, &reference);
  const double dx = dom.spacing(X);
  for (const Int3& dims : decompositions(dom.cells)) {
    CartDecomposition dec(MPI_COMM_WORLD, dom.cells, 3, dims);
    Field phi = make_phi(dec);
    fill_solid_fraction(phi, dom, ps, spec);
    EXPECT_EQ(fingerprint(phi, dom.cells, MPI_COMM_WORLD), reference) << "decomposition " << to_string(dims);
    // The particles that reach this rank's block fill it bit for bit as the whole list does
    // (what a rank of a scaling run keeps); the whole box keeps them all.
    const std::vector<Particle> near = particles_reaching(ps, dom, spec, dec.offset(), dec.local());
    Field phi_near = make_phi(dec);
    fill_solid_fraction(phi_near, dom, near, spec);
    EXPECT_EQ(fingerprint(phi_near, dom.cells, MPI_COMM_WORLD), reference) << "decomposition " << to_string(dims);
    EXPECT_EQ(particles_reaching(ps, dom, spec, {0, 0, 0}, dom.cells).size(), ps.size());

    // Against inside_particle itself, along the row through particle 0's centre that
    // crosses the x seam.
    const int gj = 8, gk = 8;
    const int j = gj - phi.offset()[Y], k = gk - phi.offset()[Z];
    if (j < 0 || j >= phi.n()[Y] || k < 0 || k >= phi.n()[Z]) continue;
    for (int i = 0; i < phi.n()[X]; ++i) {
      const int gi = phi.offset()[X] + i;
      int count = 0;
      for (int sk = 0; sk < 4; ++sk)
        for (int sj = 0; sj < 4; ++sj)
          for (int si = 0; si < 4; ++si) {
            const std::array<double, 3> pt{(gi + (si + 0.5) / 4) * dx, (gj + (sj + 0.5) / 4) * dx,
                                           (gk + (sk + 0.5) / 4) * dx};
            bool in = false;
            for (const Particle& p : ps) in = in || inside_particle(p, spec, pt, dom);
            count += in;
          }
      EXPECT_EQ(phi(i, j, k), count / 64.0) << "cell " << gi << " decomposition " << to_string(dims);
    }
  }
}

TEST(Centroids, LatticeCentresOnEveryDecomposition) {
  const Domain dom = box(7.2, 7.2, 7.2, 32);
  const ParticleSpec spec;
  const auto ps = lattice_particles(dom, -1, spec);
  const auto reference = serial_regions(dom, ps, spec, nullptr);
  // One region per particle, each on its own centre.
  ASSERT_EQ(reference.size(), ps.size());
  double worst = 0, vol_lo = 1e9, vol_hi = 0;
  for (const Particle& p : ps) {
    double best = 1e9;
    const SolidRegion* match = nullptr;
    for (const SolidRegion& r : reference) {
      const double d = cells_apart(r.centroid, p.centre, dom);
      if (d < best) best = d, match = &r;
    }
    worst = std::max(worst, best);
    EXPECT_LT(best, kCentroidTolerance) << "particle " << p.index;
    const double v = match->volume / evans_fung_volume(spec.diameter);
    vol_lo = std::min(vol_lo, v), vol_hi = std::max(vol_hi, v);
    EXPECT_EQ(match->wraps, (std::array<bool, 3>{false, false, false}));
  }
  // The region leaves out the cells at or below 1/2 and the solid in them: at 18 cells
  // per diameter that is about 8 % of the body (measured 0.906 .. 0.923 of it).
  EXPECT_GT(vol_lo, 0.85);
  EXPECT_LT(vol_hi, 1.0);
  if (world_rank() == 0)
    std::printf("[ particles ] %s cells: worst centroid error %.4f cells, region volume / body volume %.4f .. %.4f\n",
                to_string(dom.cells).c_str(), worst, vol_lo, vol_hi);

  expect_same_regions_on_every_decomposition(dom, ps, spec, reference);
}

TEST(Centroids, OffGridParticlesAndThePeriodicCorner) {
  // Lattice centres sit on cell corners, where the sampled body is point-symmetric and
  // the centroid exact; these do not.  Particle 0 at x = 0.1, z = 7.1 lies on both sides
  // of both seams, where a plain mean of in-box positions would land mid-box.
  const Domain dom = box(7.2, 7.2, 7.2, 32);
  const ParticleSpec spec;
  const std::array<double, 3> centres[] = {{0.1, 1.8, 7.1}, {3.33, 4.1, 2.05}, {5.71, 2.37, 4.93}, {2.2, 5.9, 4.4}};
  std::vector<Particle> ps;
  for (int s = 0; s < 4; ++s) ps.push_back({s, centres[s], particle_axis(s + 7, spec)});
  EXPECT_NO_THROW(check_particles(dom, ps, spec));
  const auto reference = serial_regions(dom, ps, spec, nullptr);
  ASSERT_EQ(reference.size(), ps.size());
  double worst = 0;
  for (const Particle& p : ps) {
    double best = 1e9;
    for (const SolidRegion& r : reference) best = std::min(best, cells_apart(r.centroid, p.centre, dom));
    worst = std::max(worst, best);
    EXPECT_LT(best, kCentroidTolerance) << "particle " << p.index;
  }
  for (const SolidRegion& r : reference) EXPECT_EQ(r.wraps, (std::array<bool, 3>{false, false, false}));
  if (world_rank() == 0)
    std::printf("[ particles ] %s cells, off-grid particles: worst centroid error %.4f cells\n",
                to_string(dom.cells).c_str(), worst);
  expect_same_regions_on_every_decomposition(dom, ps, spec, reference);
}

TEST(Centroids, SlabThroughTheChannelJoinsItsOwnImage) {
  // The layered case's slab: one region that meets itself across both seams, so its
  // centroid in x and z is the plain mean, and in y the middle of the channel.
  const Domain dom = box(3.6, 3.6, 3.6, 32);
  for (const Int3& dims : decompositions(dom.cells)) {
    CartDecomposition dec(MPI_COMM_WORLD, dom.cells, 3, dims);
    Field phi = make_phi(dec);
    for (int k = 0; k < phi.n()[Z]; ++k)
      for (int j = 0; j < phi.n()[Y]; ++j)
        for (int i = 0; i < phi.n()[X]; ++i) {
          const int gj = phi.offset()[Y] + j;
          phi(i, j, k) = (gj >= 8 && gj < 24) ? 1.0 : (gj == 7 ? 0.4 : 0.0);
        }
    const auto regions = solid_regions(phi, dom, dec);
    const std::string where = "decomposition " + to_string(dims);
    ASSERT_EQ(regions.size(), 1u) << where;
    const SolidRegion& r = regions[0];
    EXPECT_EQ(r.wraps, (std::array<bool, 3>{true, false, true})) << where;
    EXPECT_EQ(r.cells, 32 * 16 * 32) << where;
    EXPECT_EQ(r.first_cell, 8 * 32) << where;
    EXPECT_NEAR(r.volume, 3.6 * 1.8 * 3.6, 1e-12) << where;
    for (int ax = 0; ax < 3; ++ax) EXPECT_NEAR(r.centroid[ax], 1.8, 1e-12) << where;
  }
}

TEST(Centroids, EmptyFieldHasNoRegions) {
  const Domain dom = box(3.6, 3.6, 3.6, 32);
  CartDecomposition dec(MPI_COMM_WORLD, dom.cells, 3);
  Field phi = make_phi(dec);
  phi.fill(0.5);  // exactly 1/2 is not solid
  EXPECT_TRUE(solid_regions(phi, dom, dec).empty());
}
