#include "particles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "config_error.hpp"

namespace efsi {
namespace {

using Vec3 = std::array<double, 3>;

const char* const kAxisName[3] = {"x", "y", "z"};

// "%g" with six significant digits: what a user typed (3.6, 0.1125) reads back unchanged.
std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string vec(const Vec3& v) { return "(" + num(v[0]) + ", " + num(v[1]) + ", " + num(v[2]) + ")"; }

bool periodic(int axis) { return axis != Y; }

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// P(t), t = rho^2.  Concave with P(0) = 0.207 and P(1) = 1.087, so positive on [0, 1]:
// that is what lets the solid test compare squares instead of taking a square root.
double shape_poly(double t) { return kEvansFungC0 + t * (kEvansFungC1 + t * kEvansFungC2); }

double half_thickness_unit(double rho) {
  if (rho < 0.0 || rho >= 1.0) return 0.0;
  const double t = rho * rho;
  return 0.5 * std::sqrt(1.0 - t) * shape_poly(t);
}

// The one solid test behind inside_particle, the fill and the overlap check, on a
// displacement from the centre already reduced to the right periodic image, so that all
// three agree point by point.
inline bool inside_displacement(const Vec3& d, const Vec3& n, double radius) {
  const double zp = dot(d, n);
  const double t = (dot(d, d) - zp * zp) / (radius * radius);
  if (t >= 1.0) return false;
  const double p = shape_poly(t);
  return 4.0 * zp * zp < radius * radius * (1.0 - t) * p * p;
}

inline double nearest_image(double d, double length) { return d - length * std::round(d / length); }

inline Vec3 displacement(const Vec3& point, const Vec3& centre, const Domain& dom) {
  Vec3 d{point[0] - centre[0], point[1] - centre[1], point[2] - centre[2]};
  d[X] = nearest_image(d[X], dom.length[X]);
  d[Z] = nearest_image(d[Z], dom.length[Z]);
  return d;
}

// How far the solid reaches from the centre along a unit direction e, in units of R,
// where c = |e.n| and s = sqrt(1 - c^2): a solid point is rho R u + z' n with u a unit
// vector across the axis (e.u <= s) and |z'| < h(rho), so the reach is the maximum over
// rho of rho s + c h(rho)/R.  The profile has at most a couple of extrema, so a coarse
// scan brackets the maximum and a golden-section search refines it.
double reach_unit(double s, double c) {
  const auto g = [&](double rho) { return rho * s + c * half_thickness_unit(rho); };
  constexpr int kCoarse = 256;
  int best = kCoarse;
  double g_best = s;  // rho = 1: the rim, where the thickness vanishes
  for (int q = 0; q < kCoarse; ++q) {
    const double v = g(double(q) / kCoarse);
    if (v > g_best) g_best = v, best = q;
  }
  double a = double(std::max(0, best - 1)) / kCoarse, b = double(std::min(kCoarse, best + 1)) / kCoarse;
  const double inv_phi = (std::sqrt(5.0) - 1.0) / 2.0;
  double x1 = b - inv_phi * (b - a), x2 = a + inv_phi * (b - a);
  double g1 = g(x1), g2 = g(x2);
  for (int it = 0; it < 80 && b - a > 1e-14; ++it) {
    if (g1 < g2) {
      a = x1, x1 = x2, g1 = g2, x2 = a + inv_phi * (b - a), g2 = g(x2);
    } else {
      b = x2, x2 = x1, g2 = g1, x1 = b - inv_phi * (b - a), g1 = g(x1);
    }
  }
  return std::max({g_best, g1, g2});
}

double max_half_thickness_unit() {
  static const double h = reach_unit(0.0, 1.0);
  return h;
}

// A cheap upper bound of particle_extent (rim radius plus the thickest point), for the
// loops that only need to know which cells or pairs can be skipped.
double reach_bound(const Vec3& n, const Vec3& e, double radius) {
  const double c = std::min(1.0, std::abs(dot(n, e)));
  return radius * (std::sqrt(1.0 - c * c) + c * max_half_thickness_unit());
}

Vec3 unit(int axis) {
  Vec3 e{0.0, 0.0, 0.0};
  e[axis] = 1.0;
  return e;
}

double tilt_deg(const Vec3& n) {
  return std::acos(std::min(1.0, std::abs(n[Y]))) * 180.0 / std::numbers::pi;
}

void validate_spec(const ParticleSpec& s) {
  if (!(s.diameter > 0.0) || !std::isfinite(s.diameter))
    throw ConfigError("particle diameter " + num(s.diameter) + " must be positive");
  if (!(s.lattice > 0.0) || !std::isfinite(s.lattice))
    throw ConfigError("particle lattice cell " + num(s.lattice) + " must be positive");
  if (!(s.max_tilt_deg >= 0.0 && s.max_tilt_deg <= 90.0))
    throw ConfigError("particle max tilt " + num(s.max_tilt_deg) + " degrees must be between 0 and 90");
}

void validate_axes(const std::vector<Particle>& ps) {
  for (const Particle& p : ps) {
    const double len = std::sqrt(dot(p.axis, p.axis));
    if (!(std::abs(len - 1.0) <= 1e-9))
      throw ConfigError("particle " + std::to_string(p.index) + ": axis " + vec(p.axis) + " has length " +
                        num(len) + ", not 1");
  }
}

// Lattice cells along `axis`; the lattice tiles the box only when the length is a whole
// number of cells (otherwise sites would crowd the far wall or the periodic seam).
int lattice_cells(const Domain& dom, const ParticleSpec& s, int axis) {
  const double ratio = dom.length[axis] / s.lattice;
  const double whole = std::round(ratio);
  if (whole < 1.0 || std::abs(ratio - whole) > 1e-9 * std::max(1.0, ratio))
    throw ConfigError(std::string("domain length L") + kAxisName[axis] + " = " + num(dom.length[axis]) +
                      " is not a whole number of particle lattice cells of " + num(s.lattice) + " (" +
                      num(dom.length[axis]) + "/" + num(s.lattice) + " = " + num(ratio) + ")");
  return static_cast<int>(whole);
}

// splitmix64 (Steele, Lea and Flood 2014): fully specified here, so the orientations are
// the same with every compiler and standard library, unlike std:: distributions.
std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

double uniform01(std::uint64_t& state) { return double(splitmix64(state) >> 11) * 0x1.0p-53; }

// A point inside both solids (relative to a's centre), b at displacement d from a, or
// nothing.  Separating axes first (the two particle axes and x, y, z), which settles every
// pair of nearly parallel stacked discs; then a grid of spacing R/40 over the
// intersection of the two bounding boxes.  The spacing bounds what can be missed: a
// common region thinner than about R/40 (0.025 at D = 2, under half a paper cell).
std::optional<Vec3> common_point(const Particle& a, const Particle& b, const Vec3& d, double radius) {
  const Vec3 dirs[5] = {a.axis, b.axis, unit(X), unit(Y), unit(Z)};
  for (const Vec3& e : dirs)
    if (std::abs(dot(d, e)) >= reach_bound(a.axis, e, radius) + reach_bound(b.axis, e, radius)) return std::nullopt;
  Vec3 lo{}, hi{};
  int m[3];
  const double spacing = radius / 40.0;
  for (int ax = 0; ax < 3; ++ax) {
    const double ea = reach_bound(a.axis, unit(ax), radius), eb = reach_bound(b.axis, unit(ax), radius);
    lo[ax] = std::max(-ea, d[ax] - eb);
    hi[ax] = std::min(ea, d[ax] + eb);
    if (!(lo[ax] < hi[ax])) return std::nullopt;
    m[ax] = std::max(1, static_cast<int>(std::ceil((hi[ax] - lo[ax]) / spacing)));
  }
  for (int k = 0; k < m[Z]; ++k)
    for (int j = 0; j < m[Y]; ++j)
      for (int i = 0; i < m[X]; ++i) {
        const Vec3 p{lo[X] + (i + 0.5) * (hi[X] - lo[X]) / m[X], lo[Y] + (j + 0.5) * (hi[Y] - lo[Y]) / m[Y],
                     lo[Z] + (k + 0.5) * (hi[Z] - lo[Z]) / m[Z]};
        const Vec3 q{p[X] - d[X], p[Y] - d[Y], p[Z] - d[Z]};
        if (inside_displacement(p, a.axis, radius) && inside_displacement(q, b.axis, radius)) return p;
      }
  return std::nullopt;
}

struct Candidate {
  std::size_t a, b;
  Vec3 d;  // b's centre minus a's, nearest image
};

// Pairs whose bounding spheres (radius R) intersect, ordered by (a, b): particles binned by
// centre into cells at least 2R wide, so only the 27 neighbouring bins can hold partners.
// Sorting by bin key instead of allocating the bins keeps memory at O(particles) whatever
// diameter a user asks for.
std::vector<Candidate> sphere_pairs(const Domain& dom, const std::vector<Particle>& ps, double radius) {
  const double cut = 2.0 * radius;
  int nb[3];
  for (int ax = 0; ax < 3; ++ax)
    nb[ax] = static_cast<int>(std::clamp(std::floor(dom.length[ax] / cut), 1.0, 4096.0));
  const auto bin_of = [&](const Vec3& c) {
    std::array<int, 3> b{};
    for (int ax = 0; ax < 3; ++ax) {
      double x = c[ax] / dom.length[ax];
      x = periodic(ax) ? x - std::floor(x) : std::clamp(x, 0.0, 1.0);
      b[ax] = std::min(nb[ax] - 1, static_cast<int>(x * nb[ax]));
    }
    return b;
  };
  const auto key = [&](const std::array<int, 3>& b) {
    return std::int64_t{b[0]} + std::int64_t{nb[0]} * (b[1] + std::int64_t{nb[1]} * b[2]);
  };
  std::vector<std::pair<std::int64_t, std::size_t>> sorted(ps.size());
  for (std::size_t n = 0; n < ps.size(); ++n) sorted[n] = {key(bin_of(ps[n].centre)), n};
  std::sort(sorted.begin(), sorted.end());

  std::vector<Candidate> out;
  std::vector<std::int64_t> near;
  for (std::size_t a = 0; a < ps.size(); ++a) {
    const auto b0 = bin_of(ps[a].centre);
    near.clear();
    for (int sz = -1; sz <= 1; ++sz)
      for (int sy = -1; sy <= 1; ++sy)
        for (int sx = -1; sx <= 1; ++sx) {
          std::array<int, 3> b{b0[0] + sx, b0[1] + sy, b0[2] + sz};
          if (b[Y] < 0 || b[Y] >= nb[Y]) continue;
          b[X] = (b[X] + nb[X]) % nb[X];
          b[Z] = (b[Z] + nb[Z]) % nb[Z];
          near.push_back(key(b));
        }
    // With fewer than three bins on a periodic axis the wrapped neighbours repeat.
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    for (std::int64_t k : near) {
      auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(k, std::size_t{0}));
      for (; it != sorted.end() && it->first == k; ++it) {
        const std::size_t b = it->second;
        if (b <= a) continue;
        const Vec3 d = displacement(ps[b].centre, ps[a].centre, dom);
        if (dot(d, d) < cut * cut) out.push_back({a, b, d});
      }
    }
  }
  std::sort(out.begin(), out.end(), [](const Candidate& x, const Candidate& y) {
    return std::tie(x.a, x.b) < std::tie(y.a, y.b);
  });
  return out;
}

// Global cells along one axis that a particle's bounding box can reach, as (local, global)
// index pairs on this rank's block.  Periodic axes wrap, and list each cell once even when
// the box is wider than the domain.
void cells_in_reach(double centre, double extent, int axis, int n_global, int offset, int n_local,
                    double spacing, std::vector<std::pair<int, int>>& out) {
  out.clear();
  // One extra cell each side absorbs the rounding of the division.
  const long lo = static_cast<long>(std::floor((centre - extent) / spacing)) - 1;
  const long hi = static_cast<long>(std::floor((centre + extent) / spacing)) + 1;
  const auto take = [&](long g) {
    if (g >= offset && g < offset + n_local) out.emplace_back(static_cast<int>(g - offset), static_cast<int>(g));
  };
  if (!periodic(axis)) {
    for (long g = std::max(lo, 0L); g <= std::min(hi, long{n_global} - 1); ++g) take(g);
  } else if (hi - lo + 1 >= n_global) {
    for (long g = 0; g < n_global; ++g) take(g);
  } else {
    for (long g = lo; g <= hi; ++g) take(((g % n_global) + n_global) % n_global);
    std::sort(out.begin(), out.end());
  }
}

}  // namespace

double evans_fung_half_thickness(double rho, double radius) { return radius * half_thickness_unit(rho); }

double evans_fung_max_half_thickness(double radius) { return radius * max_half_thickness_unit(); }

double evans_fung_volume(double diameter) {
  // V = 2 int_0^R 2 pi r h(r) dr = 2 pi R^3 int_0^1 rho sqrt(1 - rho^2) P(rho^2) d rho, and
  // with u = rho^2 each term is B(k+1, 3/2)/2: 1/3, 2/15 and 8/105 for k = 0, 1, 2.
  const double r = diameter / 2.0;
  return 2.0 * std::numbers::pi * r * r * r *
         (kEvansFungC0 / 3.0 + 2.0 * kEvansFungC1 / 15.0 + 8.0 * kEvansFungC2 / 105.0);
}

bool inside_particle(const Particle& p, const ParticleSpec& spec, std::array<double, 3> point,
                     const Domain& domain) {
  return inside_displacement(displacement(point, p.centre, domain), p.axis, spec.diameter / 2.0);
}

double particle_extent(const Particle& p, const ParticleSpec& spec, int axis) {
  const double c = std::min(1.0, std::abs(p.axis[axis]));
  return spec.diameter / 2.0 * reach_unit(std::sqrt(1.0 - c * c), c);
}

std::array<double, 3> particle_axis(std::int64_t index, const ParticleSpec& spec) {
  // The site number goes through the mixer before it meets the seed, so neighbouring
  // sites (and neighbouring seeds) start from unrelated states.
  std::uint64_t mix = static_cast<std::uint64_t>(index);
  std::uint64_t state = spec.seed ^ splitmix64(mix);
  const double u_tilt = uniform01(state), u_azimuth = uniform01(state);
  // Uniform over the spherical cap, not uniform in angle: directions are then as likely
  // near the cone's edge as anywhere else on it, as for an isotropic set restricted to
  // the cone, and do not bunch at the wall normal.
  const double cos_max = std::cos(spec.max_tilt_deg * std::numbers::pi / 180.0);
  const double cos_t = 1.0 - u_tilt * (1.0 - cos_max);
  const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
  const double az = 2.0 * std::numbers::pi * u_azimuth;
  return {sin_t * std::cos(az), cos_t, sin_t * std::sin(az)};
}

std::int64_t lattice_site_count(const Domain& domain, const ParticleSpec& spec) {
  validate_spec(spec);
  std::int64_t n = 2;
  for (int ax = 0; ax < 3; ++ax) n *= lattice_cells(domain, spec, ax);
  return n;
}

std::vector<Particle> lattice_particles(const Domain& domain, int count, const ParticleSpec& spec) {
  if (count == 0) return {};
  const std::int64_t sites = lattice_site_count(domain, spec);
  if (count > sites)
    throw ConfigError("requested " + std::to_string(count) + " particles but the " + num(domain.length[X]) + " x " +
                      num(domain.length[Y]) + " x " + num(domain.length[Z]) + " domain holds only " +
                      std::to_string(sites) + " lattice sites (2 per " + num(spec.lattice) + "^3 lattice cell)");
  const std::int64_t n = count < 0 ? sites : count;
  const int bx = lattice_cells(domain, spec, X), by = lattice_cells(domain, spec, Y);
  std::vector<Particle> out;
  out.reserve(static_cast<std::size_t>(n));
  for (std::int64_t s = 0; s < n; ++s) {
    const std::int64_t b = s / 2;
    const double frac = (s % 2 == 0) ? 0.25 : 0.75;
    const std::int64_t cell[3] = {b % bx, (b / bx) % by, b / (std::int64_t{bx} * by)};
    Particle p{s, {}, particle_axis(s, spec)};
    for (int ax = 0; ax < 3; ++ax) p.centre[ax] = spec.lattice * (double(cell[ax]) + frac);
    out.push_back(p);
  }
  return out;
}

void check_particles(const Domain& domain, const std::vector<Particle>& ps, const ParticleSpec& spec) {
  validate_spec(spec);
  validate_axes(ps);
  const double radius = spec.diameter / 2.0;

  // The nearest-image solid test needs each particle to fit in the periodic box; one
  // that does not touches its own image.
  for (const Particle& p : ps)
    for (int ax : {X, Z}) {
      if (2.0 * reach_bound(p.axis, unit(ax), radius) < domain.length[ax]) continue;
      const double width = 2.0 * particle_extent(p, spec, ax);
      if (width >= domain.length[ax])
        throw ConfigError("particle " + std::to_string(p.index) + " is " + num(width) + " wide in " + kAxisName[ax] +
                          ", not less than the periodic length L" + kAxisName[ax] + " = " +
                          num(domain.length[ax]) + ": it overlaps its own periodic image (diameter " +
                          num(spec.diameter) + ")");
    }

  for (const Candidate& c : sphere_pairs(domain, ps, radius)) {
    const auto hit = common_point(ps[c.a], ps[c.b], c.d, radius);
    if (!hit) continue;
    Vec3 at{};
    for (int ax = 0; ax < 3; ++ax) {
      at[ax] = ps[c.a].centre[ax] + (*hit)[ax];
      if (periodic(ax)) at[ax] -= domain.length[ax] * std::floor(at[ax] / domain.length[ax]);
    }
    throw ConfigError("particles " + std::to_string(ps[c.a].index) + " and " + std::to_string(ps[c.b].index) +
                      " overlap: centres " + num(std::sqrt(dot(c.d, c.d))) + " apart, less than the diameter " +
                      num(spec.diameter) + ", and both solids contain " + vec(at));
  }

  const double limit = 2.0 * domain.spacing(Y);
  std::size_t failing = 0;
  std::string first;
  for (const Particle& p : ps) {
    const double e = particle_extent(p, spec, Y);
    const double below = p.centre[Y] - e, above = domain.length[Y] - (p.centre[Y] + e);
    if (std::min(below, above) >= limit) continue;
    if (failing++ == 0)
      first = "particle " + std::to_string(p.index) + " at y = " + num(p.centre[Y]) + " reaches " +
              num(std::min(below, above)) + " from the wall y = " + num(below <= above ? 0.0 : domain.length[Y]) +
              ", closer than 2 cells = " + num(limit) + " (diameter " + num(spec.diameter) + ", axis tilted " +
              num(tilt_deg(p.axis)) + " degrees from y)";
  }
  if (failing > 0)
    throw ConfigError(first + (failing > 1 ? "; " + std::to_string(failing - 1) + " more particles too close" : ""));
}

std::vector<Particle> particles_reaching(const std::vector<Particle>& particles, const Domain& domain,
                                         const ParticleSpec& spec, const Int3& offset, const Int3& n) {
  const double radius = spec.diameter / 2.0;
  std::vector<std::pair<int, int>> reach;
  std::vector<Particle> out;
  for (const Particle& p : particles) {
    bool touches = true;
    for (int ax = 0; ax < 3 && touches; ++ax) {
      cells_in_reach(p.centre[ax], reach_bound(p.axis, unit(ax), radius), ax, domain.cells[ax], offset[ax], n[ax],
                     domain.spacing(ax), reach);
      touches = !reach.empty();
    }
    if (touches) out.push_back(p);
  }
  return out;
}

void fill_solid_fraction(Field& phi, const Domain& domain, const std::vector<Particle>& particles,
                         const ParticleSpec& spec, int samples_per_axis) {
  if (phi.stagger() != Stagger::cell)
    throw std::invalid_argument("fill_solid_fraction: field " + phi.name() + " is " + to_string(phi.stagger()) +
                                ", not cell-centred");
  if (samples_per_axis < 1)
    throw ConfigError("solid-fraction samples per axis " + std::to_string(samples_per_axis) + " must be at least 1");
  validate_spec(spec);
  validate_axes(particles);
  const Int3 n = phi.n(), off = phi.offset();
  for (int ax = 0; ax < 3; ++ax)
    if (off[ax] + n[ax] > domain.cells[ax])
      throw std::invalid_argument("fill_solid_fraction: field " + phi.name() + " reaches cell " +
                                  std::to_string(off[ax] + n[ax]) + " in " + kAxisName[ax] + " of a domain of " +
                                  std::to_string(domain.cells[ax]));

#pragma omp parallel for schedule(static)
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) phi(i, j, k) = 0.0;

  const int ns = samples_per_axis;
  const double radius = spec.diameter / 2.0;
  const double h_max = evans_fung_max_half_thickness(radius);
  const Vec3 dx{domain.spacing(X), domain.spacing(Y), domain.spacing(Z)};
  const double half_diag = 0.5 * std::sqrt(dot(dx, dx));
  std::vector<double> frac(static_cast<std::size_t>(ns));
  for (int s = 0; s < ns; ++s) frac[s] = (s + 0.5) / ns;

  std::array<std::vector<std::pair<int, int>>, 3> reach;
  for (const Particle& p : particles) {
    bool touches = true;
    for (int ax = 0; ax < 3 && touches; ++ax) {
      cells_in_reach(p.centre[ax], reach_bound(p.axis, unit(ax), radius), ax, domain.cells[ax], off[ax], n[ax],
                     dx[ax], reach[ax]);
      touches = !reach[ax].empty();
    }
    if (!touches) continue;
    const auto& rx = reach[X];
    const auto& ry = reach[Y];
    const auto& rz = reach[Z];
    const int nky = static_cast<int>(rz.size() * ry.size());
    // Each particle's cells are written by one thread each; particles go one after the
    // other, so cells shared by two particles see no race.  Sample counts are small
    // integers, added exactly whatever the order.
#pragma omp parallel for schedule(static)
    for (int kj = 0; kj < nky; ++kj) {
      const auto [kl, kg] = rz[kj / ry.size()];
      const auto [jl, jg] = ry[kj % ry.size()];
      for (const auto& [il, ig] : rx) {
        // Every sample lies within half a cell diagonal of the centre, and the distance
        // to the axis and along it change no faster than the position: cells that are
        // far from the disc in either sense are skipped without sampling.
        const Vec3 cc{(ig + 0.5) * dx[X], (jg + 0.5) * dx[Y], (kg + 0.5) * dx[Z]};
        const Vec3 dc = displacement(cc, p.centre, domain);
        const double zc = dot(dc, p.axis);
        const double rc = std::sqrt(std::max(0.0, dot(dc, dc) - zc * zc));
        if (rc >= radius + half_diag || std::abs(zc) >= h_max + half_diag) continue;
        int count = 0;
        for (int sk = 0; sk < ns; ++sk)
          for (int sj = 0; sj < ns; ++sj)
            for (int si = 0; si < ns; ++si) {
              const Vec3 point{(ig + frac[si]) * dx[X], (jg + frac[sj]) * dx[Y], (kg + frac[sk]) * dx[Z]};
              count += inside_displacement(displacement(point, p.centre, domain), p.axis, radius);
            }
        phi(il, jl, kl) += count;
      }
    }
  }

  const double total = double(ns) * ns * ns;
#pragma omp parallel for schedule(static)
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) phi(i, j, k) = std::min(phi(i, j, k), total) / total;
}

}  // namespace efsi
