#include "sor_poisson.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
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
                       RegionTimers* timers, double omega, int sweeps_per_exchange, HaloPattern halo)
    : decomp_(decomp),
      x_(checked(decomp, domain, x, omega)),
      comm_(comm),
      timers_(timers),
      omega_(omega),
      k_(sweeps_per_exchange),
      xs_(&x),
      halo_(decomp, {&x}, Reach::faces, timers) {
  if (k_ < 1) throw ConfigError("SOR: sweeps per exchange " + std::to_string(k_) + " must be at least 1");
  const Int3& dims = decomp.dims();
  if (k_ > 1) {
    depth_ = 2 * k_;  // each sweep costs every colour two layers along every axis (group_boxes)
    // The passes grow into the ghosts of every face but a wall and a fused row's own x ends
    // (a periodic wrap onto the rank itself too: its deep ghosts are copies the exchange
    // makes, which keeps z free for the wavefront).  Every rank checks the smallest block
    // along each such axis, so all refuse alike.
    for (int a = 0; a < 3; ++a) {
      if (a == X && sor_fuses_colour_pairs(dims)) continue;
      for (int side : {-1, 1}) {
        Int3 step{0, 0, 0};
        step[a] = side;
        if (decomp.neighbour(step) != MPI_PROC_NULL) (side < 0 ? grows_lo_[a] : grows_hi_[a]) = true;
      }
      const int thinnest = decomp.global()[a] / dims[a];
      if ((grows_lo_[a] || grows_hi_[a]) && depth_ > thinnest)
        throw ConfigError("SOR: --sweeps-per-exchange " + std::to_string(k_) + " needs ghosts " +
                          std::to_string(depth_) + " deep (2 a sweep), more than the " + std::to_string(thinnest) +
                          " cells a rank holds along " + "xyz"[a] + "; the limit here is " +
                          std::to_string(thinnest / 2));
    }
  }
  for (int a = 0; a < 3; ++a) {
    const double h = domain.spacing(a);
    inv_h2_[a] = 1.0 / (h * h);
  }
  const Int3& n = x.n();
  const int ny_global = decomp.global()[Y];
  const int rows = n[Y] + 2 * depth_;
  wy_lo_.resize(rows);
  wy_hi_.resize(rows);
  omega_over_diag_.resize(rows);
  for (int r = 0; r < rows; ++r) {
    const int gj = x.offset()[Y] + r - depth_;
    wy_lo_[r] = gj == 0 ? 0.0 : inv_h2_[Y];
    wy_hi_[r] = gj == ny_global - 1 ? 0.0 : inv_h2_[Y];
    const double diag = 2.0 * inv_h2_[X] + 2.0 * inv_h2_[Z] + wy_lo_[r] + wy_hi_[r];
    omega_over_diag_[r] = omega / diag;
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
  if (depth_ > 0) {
    xw_ = std::make_unique<Field>(decomp, FieldSpec{x.name() + "_blocked", Stagger::cell, depth_, WallParity::even});
    rw_ = std::make_unique<Field>(decomp, FieldSpec{"sor_rhs_blocked", Stagger::cell, depth_, WallParity::even});
    wide_first_ = std::make_unique<HaloExchange>(decomp, std::vector<Field*>{xw_.get(), rw_.get()},
                                                 full_reach(halo), timers);
    wide_x_ = std::make_unique<HaloExchange>(decomp, std::vector<Field*>{xw_.get()}, full_reach(halo), timers);
    // What the first pass may update while its exchange flies: as inner_, but, phased, short
    // of the depth_ layers next to any face that is not a wall along an axis of a later
    // round: that round packs (or copies onto itself) those owned points only once the
    // rounds before it are done, after this pass has begun.
    blocked_inner_ = inner_;
    for (int a = 0; a < 3; ++a)
      for (int side : {-1, 1}) {
        Int3 step{0, 0, 0};
        step[a] = side;
        if (decomp.neighbour(step) == MPI_PROC_NULL || wide_x_->round_of_axis(a) <= 0) continue;
        if (side < 0) blocked_inner_.lo[a] = std::max(blocked_inner_.lo[a], depth_);
        else blocked_inner_.hi[a] = std::min(blocked_inner_.hi[a], n[a] - depth_);
      }
    if (blocked_inner_.empty()) blocked_inner_ = Box{};
  }
}

std::vector<Box> SorPoisson::group_boxes(int sweeps) const {
  // d[c][a]: how many layers of ghosts along axis a hold colour c's current values.  A
  // point's update is current where its neighbours are: along x those of colour c ^ 1 (one
  // layer further out), along y and z those of colour c ^ 2.  The exchange brings 2 x sweeps
  // layers; each sweep costs two (the last pass's colours end at 0, the owned points).
  int d[4][3];
  for (auto& c : d)
    for (int& v : c) v = 2 * sweeps;
  std::vector<Box> boxes;
  for (int s = 0; s < sweeps; ++s)
    for (const Stage& stage : stages_) {
      Int3 e{1 << 20, 1 << 20, 1 << 20};
      for (int c = stage.colour; c <= stage.colour + (stage.pair ? 1 : 0); ++c) {
        Int3 now;
        for (int a = 0; a < 3; ++a)
          now[a] = std::min({d[c][a], d[c ^ 1][a] - (a == X ? 1 : 0), d[c ^ 2][a] - (a == X ? 0 : 1)});
        for (int a = 0; a < 3; ++a) {
          d[c][a] = now[a];
          e[a] = std::min(e[a], now[a]);
        }
      }
      if (stage.pair)  // one box for both colours of the pass
        for (int a = 0; a < 3; ++a) d[stage.colour][a] = d[stage.colour + 1][a] = e[a];
      Box b = owned_;
      for (int a = 0; a < 3; ++a) {
        if (!grows_lo_[a] && !grows_hi_[a]) continue;  // a fused row's x: not tracked
        if (e[a] < 0) throw std::logic_error("SorPoisson: blocked ghosts too shallow (internal error)");
        if (grows_lo_[a]) b.lo[a] -= e[a];
        if (grows_hi_[a]) b.hi[a] += e[a];
      }
      boxes.push_back(b);
    }
  return boxes;
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
  sweep_stage(pass_cost(), double(b.volume()), [&] { update_loops(rhs, factor, stage, b); });
}

void SorPoisson::update_loops(const Field& rhs, double factor, const Stage& stage, const Box& b) {
  if (b.empty()) return;
  if (stage.pair && (b.lo[X] != 0 || b.hi[X] != xs_->n()[X]))
    throw std::logic_error("SorPoisson: a fused colour pair needs rows spanning the whole x extent");
  if (stage.pair) update_rows<true>(rhs, factor, stage.colour, b);
  else if (b.hi[X] - b.lo[X] <= 2) update_columns(rhs, factor, stage.colour, b);
  else update_rows<false>(rhs, factor, stage.colour, b);
}

template <bool kPair>
void SorPoisson::update_rows(const Field& rhs, double factor, int colour, const Box& b) {
  if (b.volume() >= 32768) {
#pragma omp parallel
    rows_in_team<kPair>(rhs, factor, colour, b);
  } else {
    rows_in_team<kPair>(rhs, factor, colour, b);
  }
}

// The rows shared among the threads of the enclosing team (one thread outside any), with a
// barrier at the end: a wavefront's planes follow each other in one parallel region.
template <bool kPair>
void SorPoisson::rows_in_team(const Field& rhs, double factor, int colour, const Box& b) {
  const int px = colour & 1, pyz = colour >> 1;
  Field& x = *xs_;
  const Int3& off = x.offset();
  const int nx = x.n()[X];
  const SorStencil st{inv_h2_[X], inv_h2_[Z], 1.0 - omega_, x.stride_y(), x.stride_z()};
  double* const xd = x.data();
  const double* const rd = rhs.data();
  const bool same_layout = rhs.stride_y() == st.sy && rhs.stride_z() == st.sz;
#pragma omp for collapse(2) schedule(static)
  for (int k = b.lo[Z]; k < b.hi[Z]; ++k) {
    for (int j = b.lo[Y]; j < b.hi[Y]; ++j) {
      if (((off[Y] + j + off[Z] + k) & 1) != pyz) continue;
      double* const r = xd + x.index(0, j, k);
      const double* const f = same_layout ? rd + rhs.index(0, j, k) : nullptr;
      const double wlo = wy_lo_[j + depth_], whi = wy_hi_[j + depth_], wd = omega_over_diag_[j + depth_];
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
  Field& x = *xs_;
  const Int3& off = x.offset();
  const SorStencil st{inv_h2_[X], inv_h2_[Z], 1.0 - omega_, x.stride_y(), x.stride_z()};
  for (int i = b.lo[X]; i < b.hi[X]; ++i) {
    if (((off[X] + i) & 1) != px) continue;
    for (int k = b.lo[Z]; k < b.hi[Z]; ++k) {
      int j = b.lo[Y];
      if (((off[Y] + j + off[Z] + k) & 1) != pyz) ++j;
      double* p = x.data() + x.index(i, j, k);
      for (; j < b.hi[Y]; j += 2, p += 2 * st.sy)
        *p = st.apply(p, factor * rhs(i, j, k), wy_lo_[j + depth_], wy_hi_[j + depth_], omega_over_diag_[j + depth_]);
    }
  }
}

// One pass of the sweep's passes: its share of the sweep's counted work (sor_work.hpp).
PerCell SorPoisson::pass_cost() const {
  const double passes = static_cast<double>(stages_.size());
  return (1.0 / passes) * sor_sweep_cost(static_cast<int>(passes));
}

void SorPoisson::update_interior(const Field& rhs, double factor, const Stage& stage, HaloExchange& flight,
                                 const Box& inner) {
  // In slabs of k, with a progress call after each, so that the exchange in flight moves
  // while the interior is updated (the colour of a point does not depend on the slab).
  // Under SMPI the messages move without progress calls (HaloExchange::progress), so
  // there one slab: the same modelled time in one simulator event instead of eight.
  constexpr int kSlabs = kSimulated ? 1 : 8;
  if (inner.empty()) return;
  const int nk = inner.hi[Z] - inner.lo[Z];
  for (int s = 0; s < kSlabs; ++s) {
    Box slab = inner;
    slab.lo[Z] = inner.lo[Z] + nk * s / kSlabs;
    slab.hi[Z] = inner.lo[Z] + nk * (s + 1) / kSlabs;
    {
      RegionTimers::Scope t(timers_, kSorSweepsRegion);
      update(rhs, factor, stage, slab);
    }
    flight.progress();
  }
}

// outer minus inner: the owned shell, or, blocked, the shell out to the first pass's ghosts.
void SorPoisson::update_boundary(const Field& rhs, double factor, const Stage& stage, const Box& outer,
                                 const Box& inner) {
  RegionTimers::Scope t(timers_, kSorSweepsRegion);
  // The shell's boxes (up to 26) are one stage: in the simulation build one charge, the
  // same modelled time in a twentieth of the simulator's events.
  sweep_stage(pass_cost(), double(outer.volume() - inner.volume()), [&] {
    for_each_shell_box(outer, inner, [&](const Box& b) { update_loops(rhs, factor, stage, b); });
  });
}

void SorPoisson::blocked_passes(const Field& rhs, double factor, int first, const std::vector<Box>& boxes) {
  RegionTimers::Scope t(timers_, kSorSweepsRegion);
  const int p = static_cast<int>(boxes.size());
  double cells = 0;
  for (int m = first; m < p; ++m) cells += double(boxes[m].volume());
  // The group's passes are one stage (one charge in the simulation build).
  sweep_stage(pass_cost(), cells, [&] { wavefront(rhs, factor, first, boxes); });
}

void SorPoisson::wavefront(const Field& rhs, double factor, int first, const std::vector<Box>& boxes) {
  const int p = static_cast<int>(boxes.size());
  // A wavefront over z planes: pass m takes plane k after pass m - 1 has taken k + 1 and
  // before pass m + 1 takes k - 1.  What pass m reads at planes k and k +- 1 was last written
  // by a pass m' < m at a step m' + k' < m + k (or the same step, m' = m - 1, k' = k + 1,
  // earlier in it), and is next written at a step >= m + k (the same, m + 1 at k - 1, later
  // in it): the passes see the values they would one after another.  A plane is read from
  // memory about once a group, not once a pass.  One parallel region for the wavefront: the
  // threads share each plane's rows.
  const int passes = static_cast<int>(stages_.size());
  int t0 = std::numeric_limits<int>::max(), t1 = std::numeric_limits<int>::min();
  for (int m = first; m < p; ++m) {
    t0 = std::min(t0, boxes[m].lo[Z] + m);
    t1 = std::max(t1, boxes[m].hi[Z] - 1 + m);
  }
#pragma omp parallel
  for (int step = t0; step <= t1; ++step)
    for (int m = first; m < p; ++m) {
      Box b = boxes[m];
      const int k = step - m;
      if (k < b.lo[Z] || k >= b.hi[Z]) continue;
      b.lo[Z] = k;
      b.hi[Z] = k + 1;
      const Stage& stage = stages_[m % passes];
      if (stage.pair) rows_in_team<true>(rhs, factor, stage.colour, b);
      else rows_in_team<false>(rhs, factor, stage.colour, b);
    }
}

void SorPoisson::sweeps(const Field& rhs, int n, double factor) {
  if (n <= 0) return;
  if (depth_ > 0) return blocked_sweeps(rhs, n, factor);
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
        update_interior(rhs, factor, stage, *flight, inner_);
        flight->finish();
        update_boundary(rhs, factor, stage, owned_, inner_);
        flight = &after(m++);
        flight->begin();
      }
    flight->finish();
  }
}

void SorPoisson::blocked_sweeps(const Field& rhs, int n, double factor) {
  // Owned x and rhs into the deep fields; their ghosts travel with the first exchange.
  {
    RegionTimers::Scope t(timers_, Region::halo_pack);
    compute_stage(PerCell{32, 0}, double(owned_.volume()), [&] {
      xw_->copy_owned_from(x_);
      rw_->copy_owned_from(rhs);
    });
  }
  xs_ = xw_.get();
  HaloExchange* flight = wide_first_.get();
  const std::vector<Box> full = group_boxes(k_), rest = n % k_ ? group_boxes(n % k_) : std::vector<Box>{};
  for (int done = 0; done < n; done += k_) {
    const std::vector<Box>& boxes = n - done >= k_ ? full : rest;
    if (comm_ == CommMode::sync || flight->messages_sent() == 0) {
      flight->exchange();
      blocked_passes(*rw_, factor, 0, boxes);
    } else {
      flight->begin();
      update_interior(*rw_, factor, stages_[0], *flight, blocked_inner_);
      flight->finish();
      update_boundary(*rw_, factor, stages_[0], boxes[0], blocked_inner_);
      blocked_passes(*rw_, factor, 1, boxes);
    }
    flight = wide_x_.get();
  }
  xs_ = &x_;
  {
    RegionTimers::Scope t(timers_, Region::halo_pack);
    compute_stage(PerCell{16, 0}, double(owned_.volume()), [&] { x_.copy_owned_from(*xw_); });
  }
  halo_.exchange();
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
