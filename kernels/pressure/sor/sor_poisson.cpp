#include "sor_poisson.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "compute_model.hpp"
#include "config_error.hpp"
#include "laplacian.hpp"
#include "sor_work.hpp"

namespace efsi {

void check_sor_grid(const Int3& cells) {
  // The colouring (i mod 2) + 2 ((j + k) mod 2) would give neighbours across the wrap the
  // same colour.
  if (cells[X] % 2 != 0 || cells[Z] % 2 != 0)
    throw ConfigError("method sor needs even cell counts in x and z (four-colour ordering across the periodic "
                      "wrap); cells are " + to_string(cells));
}

namespace {

// Runs before the HaloExchange member is built, so that a bad set-up throws on every
// rank before anything collective.
Field& checked(const CartDecomposition& decomp, const Domain& domain, Field& x, double omega) {
  const Int3& g = decomp.global();
  check_sor_grid(g);
  if (domain.cells != g)
    throw ConfigError("SOR: domain cells " + to_string(domain.cells) + " differ from the decomposition's grid " +
                      to_string(g));
  if (x.stagger() != Stagger::cell || x.halo() < 1 || x.spec().parity != WallParity::even)
    throw ConfigError("SOR: field '" + x.name() + "' must be cell-centred with halo >= 1 and even wall parity");
  if (x.n() != decomp.local() || x.offset() != decomp.offset())
    throw ConfigError("SOR: field '" + x.name() + "' does not belong to this decomposition");
  if (!(omega > 0.0 && omega < 2.0)) throw ConfigError("SOR: omega must lie in (0, 2), got " + std::to_string(omega));
  return x;
}

}  // namespace

SorPoisson::SorPoisson(const CartDecomposition& decomp, const Domain& domain, Field& x, CommMode comm,
                       RegionTimers* timers, double omega)
    : decomp_(decomp),
      x_(checked(decomp, domain, x, omega)),
      comm_(comm),
      timers_(timers),
      omega_(omega),
      halo_(decomp, {&x}, Reach::faces, timers) {
  for (int a = 0; a < 3; ++a) {
    const double h = domain.spacing(a);
    inv_h2_[a] = 1.0 / (h * h);
  }
  const Int3& n = x.n();
  const int ny_global = decomp.global()[Y];
  wy_lo_.resize(n[Y]);
  wy_hi_.resize(n[Y]);
  omega_over_diag_.resize(n[Y]);
  for (int j = 0; j < n[Y]; ++j) {
    const int gj = x.offset()[Y] + j;
    wy_lo_[j] = gj == 0 ? 0.0 : inv_h2_[Y];
    wy_hi_[j] = gj == ny_global - 1 ? 0.0 : inv_h2_[Y];
    const double diag = 2.0 * inv_h2_[X] + 2.0 * inv_h2_[Z] + wy_lo_[j] + wy_hi_[j];
    omega_over_diag_[j] = omega / diag;
  }
  owned_ = Box{{0, 0, 0}, n};
  // The async interior stops one cell short only of faces whose neighbour is another
  // rank: across a wall the ghost's weight is zero, and a rank that is its own periodic
  // neighbour has its ghosts copied locally when the exchange begins. (The weak-scaling
  // grid 2x1x1 thus leaves just the two x faces for after the wait.)
  inner_ = owned_;
  for (int a = 0; a < 3; ++a)
    for (int side : {-1, 1}) {
      Int3 step{0, 0, 0};
      step[a] = side;
      const int peer = decomp.neighbour(step);
      if (peer == MPI_PROC_NULL || peer == decomp.rank()) continue;
      (side < 0 ? inner_.lo[a] : inner_.hi[a]) = side < 0 ? 1 : n[a] - 1;
    }
  if (inner_.empty()) inner_ = Box{};  // for_each_shell_box: everything is boundary
  // Colours 0 and 1 (and 2 and 3) share their rows and meet only along x: where x is whole
  // on this rank, a row can take both in one pass, the second after the row's own ends
  // are copied into its x ghosts. The values are those of four separate passes, bit for
  // bit, with half the passes over memory and half the exchanges.
  if (sor_fuses_colour_pairs(decomp.dims())) {
    stages_ = {{0, true}, {2, true}};
    stage_halo_ = std::make_unique<HaloExchange>(decomp, std::vector<Field*>{&x}, Reach::faces, timers,
                                                 std::array<bool, 3>{false, true, true});
  } else {
    stages_ = {{0, false}, {1, false}, {2, false}, {3, false}};
  }
}

// One point's SOR update: the single formula every loop below uses, so that rows and
// columns give bitwise the same values.
struct SorStencil {
  double ax, az, keep;
  std::ptrdiff_t sy, sz;
  double apply(double* p, double rhs_scaled, double wlo, double whi, double wd) const {
    const double s = ax * (p[-1] + p[1]) + (wlo * p[-sy] + whi * p[sy]) + az * (p[-sz] + p[sz]) - rhs_scaled;
    return keep * p[0] + wd * s;
  }
};

void SorPoisson::update(const Field& rhs, double factor, const Stage& stage, const Box& b) {
  if (b.empty()) return;
  if (stage.pair && (b.lo[X] != 0 || b.hi[X] != x_.n()[X]))
    throw std::logic_error("SorPoisson: a fused colour pair needs rows spanning the whole x extent");
  sweep_stage(pass_cost(), double(b.volume()), [&] {
    if (stage.pair) update_rows<true>(rhs, factor, stage.colour, b);
    else if (b.hi[X] - b.lo[X] <= 2) update_columns(rhs, factor, stage.colour, b);
    else update_rows<false>(rhs, factor, stage.colour, b);
  });
}

template <bool kPair>
void SorPoisson::update_rows(const Field& rhs, double factor, int colour, const Box& b) {
  const int px = colour & 1, pyz = colour >> 1;
  const Int3& off = x_.offset();
  const int nx = x_.n()[X];
  const SorStencil st{inv_h2_[X], inv_h2_[Z], 1.0 - omega_, x_.stride_y(), x_.stride_z()};
  double* const xd = x_.data();
  const double* const rd = rhs.data();
  const bool same_layout = rhs.stride_y() == st.sy && rhs.stride_z() == st.sz;
#pragma omp parallel for collapse(2) schedule(static) if (b.volume() >= 32768)
  for (int k = b.lo[Z]; k < b.hi[Z]; ++k) {
    for (int j = b.lo[Y]; j < b.hi[Y]; ++j) {
      if (((off[Y] + j + off[Z] + k) & 1) != pyz) continue;
      double* const r = xd + x_.index(0, j, k);
      const double* const f = same_layout ? rd + rhs.index(0, j, k) : nullptr;
      const double wlo = wy_lo_[j], whi = wy_hi_[j], wd = omega_over_diag_[j];
      for (int c = 0; c < (kPair ? 2 : 1); ++c) {
        if (kPair) {
          // The row is the whole periodic x extent (sor_fuses_colour_pairs): its own ends
          // are its x ghosts, as an exchange before each colour would have set them.
          r[-1] = r[nx - 1];
          r[nx] = r[0];
        }
        int i0 = b.lo[X];
        if (((off[X] + i0) & 1) != (px ^ c)) ++i0;
        if (same_layout) {
#pragma omp simd
          for (int i = i0; i < b.hi[X]; i += 2) r[i] = st.apply(r + i, factor * f[i], wlo, whi, wd);
        } else {
          for (int i = i0; i < b.hi[X]; i += 2) r[i] = st.apply(r + i, factor * rhs(i, j, k), wlo, whi, wd);
        }
      }
    }
  }
}

// The x faces of the boundary shell are one cell wide: a row walk would set up a row for
// one point or none, which cost more than the points themselves (about a quarter of a
// sweep at 64^3). Here a face whose x parity is not the colour's is skipped whole, and the
// others are walked down their columns, two cells a step in j.
void SorPoisson::update_columns(const Field& rhs, double factor, int colour, const Box& b) {
  const int px = colour & 1, pyz = colour >> 1;
  const Int3& off = x_.offset();
  const SorStencil st{inv_h2_[X], inv_h2_[Z], 1.0 - omega_, x_.stride_y(), x_.stride_z()};
  for (int i = b.lo[X]; i < b.hi[X]; ++i) {
    if (((off[X] + i) & 1) != px) continue;
    for (int k = b.lo[Z]; k < b.hi[Z]; ++k) {
      int j = b.lo[Y];
      if (((off[Y] + j + off[Z] + k) & 1) != pyz) ++j;
      double* p = x_.data() + x_.index(i, j, k);
      for (; j < b.hi[Y]; j += 2, p += 2 * st.sy)
        *p = st.apply(p, factor * rhs(i, j, k), wy_lo_[j], wy_hi_[j], omega_over_diag_[j]);
    }
  }
}

// One pass of the sweep's passes: its share of the sweep's counted work (sor_work.hpp).
PerCell SorPoisson::pass_cost() const {
  const double passes = static_cast<double>(stages_.size());
  return (1.0 / passes) * sor_sweep_cost(static_cast<int>(passes));
}

void SorPoisson::update_interior(const Field& rhs, double factor, const Stage& stage, HaloExchange& flight) {
  // In slabs of k, with a progress call after each, so that the exchange in flight moves
  // while the interior is updated (the colour of a point does not depend on the slab).
  // Under SMPI the messages move without progress calls (HaloExchange::progress), so
  // there one slab: the same modelled time in one simulator event instead of eight.
  constexpr int kSlabs = kSimulated ? 1 : 8;
  if (inner_.empty()) return;
  const int nk = inner_.hi[Z] - inner_.lo[Z];
  for (int s = 0; s < kSlabs; ++s) {
    Box slab = inner_;
    slab.lo[Z] = inner_.lo[Z] + nk * s / kSlabs;
    slab.hi[Z] = inner_.lo[Z] + nk * (s + 1) / kSlabs;
    {
      RegionTimers::Scope t(timers_, kSorSweepsRegion);
      update(rhs, factor, stage, slab);
    }
    flight.progress();
  }
}

void SorPoisson::update_boundary(const Field& rhs, double factor, const Stage& stage) {
  RegionTimers::Scope t(timers_, kSorSweepsRegion);
  // The simulation build charges the shell's boxes (up to 26) as one: the same modelled
  // time, a twentieth of the simulator's events.
  if constexpr (kSimulated) {
    charge_compute(pass_cost(), double(owned_.volume() - inner_.volume()), Efficiency::sweeps);
    return;
  }
  for_each_shell_box(owned_, inner_, [&](const Box& b) { update(rhs, factor, stage, b); });
}

void SorPoisson::sweeps(const Field& rhs, int n, double factor) {
  if (n <= 0) return;
  // The exchange after stage m of the n sweeps: between stages, or whole after the last.
  const long last = static_cast<long>(n) * static_cast<long>(stages_.size()) - 1;
  auto after = [&](long m) -> HaloExchange& { return m == last ? halo_ : between_stages(); };
  long m = 0;
  // With no message to overlap (every neighbour this rank itself), async runs as sync.
  if (comm_ == CommMode::sync || halo_.messages_sent() == 0) {
    halo_.exchange();
    for (int s = 0; s < n; ++s)
      for (const Stage& stage : stages_) {
        {
          RegionTimers::Scope t(timers_, kSorSweepsRegion);
          update(rhs, factor, stage, owned_);
        }
        after(m++).exchange();
      }
  } else {
    // The exchange in flight always carries the previous stage (or the caller's field).
    HaloExchange* flight = &halo_;
    flight->begin();
    for (int s = 0; s < n; ++s)
      for (const Stage& stage : stages_) {
        update_interior(rhs, factor, stage, *flight);
        flight->finish();
        update_boundary(rhs, factor, stage);
        flight = &after(m++);
        flight->begin();
      }
    flight->finish();
  }
}

double SorPoisson::residual_rms(const Field& rhs, double factor) {
  halo_.exchange();
  const Int3& n = x_.n();
  double sum = 0.0;
#pragma omp parallel for collapse(2) schedule(static) reduction(+ : sum)
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) {
        const double r = factor * rhs(i, j, k) - laplacian(x_, inv_h2_, i, j, k);
        sum += r * r;
      }
  double total = 0.0;
  {
    RegionTimers::Scope t(timers_, Region::reduce);
    MPI_Allreduce(&sum, &total, 1, MPI_DOUBLE, MPI_SUM, decomp_.comm());
  }
  return std::sqrt(total / static_cast<double>(product(decomp_.global())));
}

}  // namespace efsi
