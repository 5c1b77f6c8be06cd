#pragma once
// Biconcave particles (docs/numerics.md, "Particles"): the Evans-Fung shape, the body-centred cubic
// placement with seeded orientations, the placement checks, and the initial solid
// fraction phi0 that every experiment starts from.
//
// Everything here is a function of global quantities only (domain, lattice-site number,
// seed, global cell index), so that every rank count and decomposition builds bitwise the
// same particles and the same phi0.
#include <array>
#include <cstdint>
#include <vector>

#include "domain.hpp"
#include "field.hpp"

namespace efsi {

struct ParticleSpec {
  double diameter = 2.0;        // 2R
  double lattice = 3.6;         // edge of the cubic lattice cell; two sites per cell
  double max_tilt_deg = 30.0;   // largest angle between a particle's axis and the wall normal y
  std::uint64_t seed = 12345;   // with the site number, the only input of the orientation
};

struct Particle {
  std::int64_t index;              // global lattice-site number (any label for hand-made ones)
  std::array<double, 3> centre;
  std::array<double, 3> axis;      // unit vector: the particle frame's z'
};

// Evans-Fung profile: at rho = r/R < 1 the solid is |z'| < (R/2) sqrt(1 - rho^2) P(rho^2),
// P(t) = C0 + C1 t + C2 t^2.
inline constexpr double kEvansFungC0 = 0.207161;
inline constexpr double kEvansFungC1 = 2.002558;
inline constexpr double kEvansFungC2 = -1.122762;

// Half-thickness at rho = r/R in [0, 1] (0 outside).
double evans_fung_half_thickness(double rho, double radius);
// The largest half-thickness, 0.32809 R at rho = 0.70: the solid lies in |z'| < this.
double evans_fung_max_half_thickness(double radius);
// Exact volume: 2 pi R^3 (C0/3 + 2 C1/15 + 8 C2/105) = 1.574049... R^3.
double evans_fung_volume(double diameter);

// Whether `point` is solid: minimum image in x and z (periodic), none in y (walls).
bool inside_particle(const Particle& p, const ParticleSpec& spec, std::array<double, 3> point,
                     const Domain& domain);

// Half-width of the particle's solid along `axis` (exact to ~1e-12 R): its axis-aligned
// bounding box is centre -+ this.
double particle_extent(const Particle& p, const ParticleSpec& spec, int axis);

// Orientation of lattice site `index`: tilted from y by at most max_tilt_deg, uniformly
// over that spherical cap, with uniform azimuth; from (seed, index) alone.
std::array<double, 3> particle_axis(std::int64_t index, const ParticleSpec& spec);

// Sites of the body-centred cubic lattice in the domain: 2 per lattice cell.  Throws
// ConfigError naming the numbers when a length is not a whole number of lattice cells.
std::int64_t lattice_site_count(const Domain& domain, const ParticleSpec& spec = {});

// The first `count` lattice sites (count < 0: all of them), site s in lattice cell s / 2
// (x fastest, then y, then z) at lattice * (b + 1/4) for even s and (b + 3/4) for odd s.
// count = 0 returns no particles and accepts any domain (the no-particle cases).  Throws
// ConfigError when count exceeds the sites or the domain is not a whole number of cells.
std::vector<Particle> lattice_particles(const Domain& domain, int count, const ParticleSpec& spec = {});

// Throws ConfigError (one line: indices, distance, limit) when a particle's axis is not a
// unit vector, a particle overlaps its own periodic image, two particles' solids
// intersect (bounding spheres first, then sampling on a grid of spacing R/40 inside both
// bounding boxes), or a solid point comes within 2 * spacing(Y) of a wall.
void check_particles(const Domain& domain, const std::vector<Particle>& particles, const ParticleSpec& spec = {});

// phi on every owned cell of a cell-centred field = fraction of the samples_per_axis^3
// points of a regular sub-grid (sub-cell midpoints) inside any particle, clamped to
// [0, 1].  Ghosts are left as they are: the caller exchanges halos.  Not collective: each
// rank fills its own block, from global cell indices only, so phi is bitwise the same for
// every decomposition and thread count.
void fill_solid_fraction(Field& phi, const Domain& domain, const std::vector<Particle>& particles,
                         const ParticleSpec& spec = {}, int samples_per_axis = 4);

// The particles whose bounding box reaches a cell of the block of `n` cells at global
// `offset`: all that fill_solid_fraction needs on that block.  A rank of a weak-scaling
// run keeps these (a few) instead of the whole lattice (2 a rank, 0.9 MB each at 8192 ranks).
std::vector<Particle> particles_reaching(const std::vector<Particle>& particles, const Domain& domain,
                                         const ParticleSpec& spec, const Int3& offset, const Int3& n);

}  // namespace efsi
