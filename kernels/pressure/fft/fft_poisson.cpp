#include "fft_poisson.hpp"

#include <fftw3.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <functional>
#include <mutex>
#include <numbers>
#include <string>

#include "config_error.hpp"

namespace efsi {

namespace {

// Index box [lo, hi) in a global index space, stored with axis ord[0] fastest.
struct Layout {
  Int3 lo{}, hi{};
  Int3 ord{0, 1, 2};
  std::int64_t ext(int a) const { return hi[a] - lo[a]; }
  std::int64_t volume() const {
    for (int a = 0; a < 3; ++a)
      if (hi[a] <= lo[a]) return 0;
    return ext(0) * ext(1) * ext(2);
  }
  std::int64_t pos(const Int3& g) const {
    return (g[ord[0]] - lo[ord[0]]) +
           ext(ord[0]) * ((g[ord[1]] - lo[ord[1]]) + ext(ord[1]) * (g[ord[2]] - lo[ord[2]]));
  }
};

// Balanced split of n into p parts: part i is [lo, hi).
int split_lo(int n, int p, int i) { return static_cast<int>(std::int64_t{n} * i / p); }

Layout intersect(const Layout& a, const Layout& b) {
  Layout r;
  for (int d = 0; d < 3; ++d) {
    r.lo[d] = std::max(a.lo[d], b.lo[d]);
    r.hi[d] = std::min(a.hi[d], b.hi[d]);
  }
  return r;
}

// Visits every point of `box` in canonical order (axis 0 fastest, then 1, then 2).
template <class F>
void for_each_point(const Layout& box, F&& f) {
  if (box.volume() == 0) return;
  Int3 g;
  for (g[2] = box.lo[2]; g[2] < box.hi[2]; ++g[2])
    for (g[1] = box.lo[1]; g[1] < box.hi[1]; ++g[1])
      for (g[0] = box.lo[0]; g[0] < box.hi[0]; ++g[0]) f(g);
}

// Builds the transpose inside `comm` from each member's `src(coords)` box to its
// `dst(coords)` box; coords are the members' Cartesian coordinates in the full grid.
void build_transpose(FftPoisson::Transpose& t, MPI_Comm comm, const Int3& my_coords, int elem,
                     const std::function<Layout(const Int3&)>& src,
                     const std::function<Layout(const Int3&)>& dst) {
  t.comm = comm;
  t.elem = elem;
  int size = 1, rank = 0;
  MPI_Comm_size(comm, &size);
  MPI_Comm_rank(comm, &rank);
  std::vector<int> all(3 * size);
  MPI_Allgather(my_coords.data(), 3, MPI_INT, all.data(), 3, MPI_INT, comm);
  const Layout my_src = src(my_coords), my_dst = dst(my_coords);
  t.volume = my_src.volume();
  t.send_counts.assign(size, 0);
  t.send_displs.assign(size, 0);
  t.recv_counts.assign(size, 0);
  t.recv_displs.assign(size, 0);
  t.send_idx.clear();
  t.recv_idx.clear();
  for (int p = 0; p < size; ++p) {
    const Int3 c{all[3 * p], all[3 * p + 1], all[3 * p + 2]};
    const Layout out = intersect(my_src, dst(c));
    const Layout in = intersect(src(c), my_dst);
    t.send_displs[p] = static_cast<int>(t.send_idx.size() * elem);
    t.recv_displs[p] = static_cast<int>(t.recv_idx.size() * elem);
    for_each_point(out, [&](const Int3& g) { t.send_idx.push_back(my_src.pos(g)); });
    for_each_point(in, [&](const Int3& g) { t.recv_idx.push_back(my_dst.pos(g)); });
    t.send_counts[p] = static_cast<int>(t.send_idx.size() * elem) - t.send_displs[p];
    t.recv_counts[p] = static_cast<int>(t.recv_idx.size() * elem) - t.recv_displs[p];
  }
  if (static_cast<std::int64_t>(t.send_idx.size()) != my_src.volume() ||
      static_cast<std::int64_t>(t.recv_idx.size()) != my_dst.volume())
    throw ConfigError("FftPoisson: pencil layouts do not cover the block (internal error)");
  t.identity = size == 1 && my_src.lo == my_dst.lo && my_src.hi == my_dst.hi && my_src.ord == my_dst.ord;
  if (t.identity) {  // no index lists or buffers: forward and backward copy the block
    t.send_idx.clear();
    t.recv_idx.clear();
    return;
  }
  t.send_buf.resize(t.send_idx.size() * elem);
  t.recv_buf.resize(t.recv_idx.size() * elem);
}

template <int E>
void gather(const std::vector<std::int64_t>& idx, const double* src, double* buf) {
  const std::int64_t n = static_cast<std::int64_t>(idx.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t m = 0; m < n; ++m)
    for (int e = 0; e < E; ++e) buf[E * m + e] = src[E * idx[m] + e];
}

template <int E>
void scatter(const std::vector<std::int64_t>& idx, const double* buf, double* dst) {
  const std::int64_t n = static_cast<std::int64_t>(idx.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t m = 0; m < n; ++m)
    for (int e = 0; e < E; ++e) dst[E * idx[m] + e] = buf[E * m + e];
}

template <int E>
void permute(const std::vector<std::int64_t>& out_idx, const std::vector<std::int64_t>& in_idx, const double* from,
             double* to) {
  const std::int64_t n = static_cast<std::int64_t>(out_idx.size());
#pragma omp parallel for schedule(static)
  for (std::int64_t m = 0; m < n; ++m)
    for (int e = 0; e < E; ++e) to[E * in_idx[m] + e] = from[E * out_idx[m] + e];
}

void exchange(const std::vector<std::int64_t>& out_idx, const std::vector<std::int64_t>& in_idx, const double* from,
              double* to, int elem, std::vector<double>& sbuf, std::vector<double>& rbuf, const std::vector<int>& sc,
              const std::vector<int>& sd, const std::vector<int>& rc, const std::vector<int>& rd, MPI_Comm comm,
              double& mpi_seconds) {
  if (sc.size() == 1) {  // a one-rank sub-communicator: a local reordering, no MPI
    if (elem == 1) permute<1>(out_idx, in_idx, from, to);
    else permute<2>(out_idx, in_idx, from, to);
    return;
  }
  if (elem == 1) gather<1>(out_idx, from, sbuf.data());
  else gather<2>(out_idx, from, sbuf.data());
  const double t0 = MPI_Wtime();
  MPI_Alltoallv(sbuf.data(), sc.data(), sd.data(), MPI_DOUBLE, rbuf.data(), rc.data(), rd.data(), MPI_DOUBLE, comm);
  mpi_seconds += MPI_Wtime() - t0;
  if (elem == 1) scatter<1>(in_idx, rbuf.data(), to);
  else scatter<2>(in_idx, rbuf.data(), to);
}

std::once_flag fftw_threads_once;

}  // namespace

void FftPoisson::Transpose::forward(const double* src, double* dst) {
  if (identity) {
    if (dst != src) std::memcpy(dst, src, sizeof(double) * static_cast<std::size_t>(elem) * static_cast<std::size_t>(volume));
    return;
  }
  exchange(send_idx, recv_idx, src, dst, elem, send_buf, recv_buf, send_counts, send_displs, recv_counts,
           recv_displs, comm, mpi_seconds);
}

void FftPoisson::Transpose::backward(const double* dst, double* src) {
  if (identity) {
    if (src != dst) std::memcpy(src, dst, sizeof(double) * static_cast<std::size_t>(elem) * static_cast<std::size_t>(volume));
    return;
  }
  exchange(recv_idx, send_idx, dst, src, elem, recv_buf, send_buf, recv_counts, recv_displs, send_counts,
           send_displs, comm, mpi_seconds);
}

void FftPoisson::FftwBuf::operator()(void* p) const noexcept { fftw_free(p); }

FftPoisson::FftPoisson(const CartDecomposition& decomp, const Domain& domain, Planning planning, RegionTimers* timers)
    : timers_(timers) {
  n_global_ = decomp.global();
  n_local_ = decomp.local();
  if (domain.cells != n_global_)
    throw ConfigError("FftPoisson: domain cells " + to_string(domain.cells) + " differ from the decomposition's " +
                      to_string(n_global_));
  for (int a = 0; a < 3; ++a) inv_h2_[a] = 1.0 / (domain.spacing(a) * domain.spacing(a));
  const int NX = n_global_[X], NY = n_global_[Y], NZ = n_global_[Z];
  const Int3 P = decomp.dims();
  const Int3 me = decomp.coords();
  for (int a = 0; a < 3; ++a)
    if (decomp.offset()[a] != split_lo(n_global_[a], P[a], me[a]))
      throw ConfigError("FftPoisson: unexpected block offsets (internal error)");
  mx_ = NX / 2 + 1;
  const int MX = mx_;
  const Int3 NG = n_global_;

  // The four layouts, as functions of a rank's Cartesian coordinates.
  auto block = [=](const Int3& c) {
    Layout l;
    for (int a = 0; a < 3; ++a) l.lo[a] = split_lo(NG[a], P[a], c[a]), l.hi[a] = split_lo(NG[a], P[a], c[a] + 1);
    l.ord = {0, 1, 2};
    return l;
  };
  auto ysub = [=](const Int3& c, int& lo, int& hi) {  // Y_cy split Px ways, part cx
    const int y0 = split_lo(NY, P[Y], c[Y]), ny = split_lo(NY, P[Y], c[Y] + 1) - y0;
    lo = y0 + split_lo(ny, P[X], c[X]);
    hi = y0 + split_lo(ny, P[X], c[X] + 1);
  };
  auto xpencil = [=](const Int3& c, int nxr) {
    Layout l = block(c);
    l.lo[X] = 0, l.hi[X] = nxr;
    ysub(c, l.lo[Y], l.hi[Y]);
    l.ord = {0, 1, 2};
    return l;
  };
  auto zpencil = [=](const Int3& c) {
    Layout l;
    l.lo[X] = split_lo(MX, P[Z], c[Z]), l.hi[X] = split_lo(MX, P[Z], c[Z] + 1);
    ysub(c, l.lo[Y], l.hi[Y]);
    l.lo[Z] = 0, l.hi[Z] = NZ;
    // z fastest for the z transforms where z is split; else the x-pencil's order, and the
    // transpose from it is a copy (the z transforms then run strided).
    l.ord = P[Z] > 1 ? Int3{2, 0, 1} : Int3{0, 1, 2};
    return l;
  };
  auto ypencil = [=](const Int3& c) {
    Layout l;
    l.lo[X] = split_lo(MX, P[Z], c[Z]), l.hi[X] = split_lo(MX, P[Z], c[Z] + 1);
    l.lo[Y] = 0, l.hi[Y] = NY;
    const int pxy = P[X] * P[Y], r = c[X] * P[Y] + c[Y];
    l.lo[Z] = split_lo(NZ, pxy, r), l.hi[Z] = split_lo(NZ, pxy, r + 1);
    // y never fastest: the tridiagonal solves vectorise across the lines.  With x and y
    // whole the z-pencil's order, so that the transpose from it is a copy.
    l.ord = pxy == 1 ? (P[Z] > 1 ? Int3{2, 0, 1} : Int3{0, 1, 2}) : Int3{0, 1, 2};
    return l;
  };

  comm_x_ = decomp.sub_comm({true, false, false});
  comm_z_ = decomp.sub_comm({false, false, true});
  comm_xy_ = decomp.sub_comm({true, true, false});
  build_transpose(t1_, comm_x_, me, 1, block, [&](const Int3& c) { return xpencil(c, NX); });
  build_transpose(t2_, comm_z_, me, 2, [&](const Int3& c) { return xpencil(c, MX); }, zpencil);
  build_transpose(t3_, comm_xy_, me, 2, zpencil, ypencil);

  const Layout l0 = block(me), l1 = xpencil(me, NX), l2 = zpencil(me), l3 = ypencil(me);
  lines_x_ = l1.ext(Y) * l1.ext(Z);
  lines_z_ = l2.volume() / NZ;

  auto alloc = [](std::int64_t doubles) { return Buf(fftw_alloc_real(static_cast<size_t>(std::max<std::int64_t>(doubles, 2)))); };
  // A transpose that is a copy shares its buffers instead.
  b0_ = alloc(l0.volume());
  p0_ = b0_.get();
  if (!t1_.identity) b1_ = alloc(l1.volume());
  p1_ = t1_.identity ? p0_ : b1_.get();
  b1c_ = alloc(2 * lines_x_ * MX);
  p1c_ = b1c_.get();
  if (!t2_.identity) b2_ = alloc(2 * l2.volume());
  p2_ = t2_.identity ? p1c_ : b2_.get();
  if (!t3_.identity) b3_ = alloc(2 * l3.volume());
  p3_ = t3_.identity ? p2_ : b3_.get();

  std::call_once(fftw_threads_once, [] { fftw_init_threads(); });
  fftw_plan_with_nthreads(omp_get_max_threads());
  const unsigned flags = planning == Planning::measure ? FFTW_MEASURE : FFTW_ESTIMATE;
  if (lines_x_ > 0) {
    int n[1] = {NX};
    const int how = static_cast<int>(lines_x_);
    auto* c = reinterpret_cast<fftw_complex*>(p1c_);
    plan_r2c_ = fftw_plan_many_dft_r2c(1, n, how, p1_, nullptr, 1, NX, c, nullptr, 1, MX, flags);
    plan_c2r_ = fftw_plan_many_dft_c2r(1, n, how, c, nullptr, 1, MX, p1_, nullptr, 1, NX, flags);
  }
  if (lines_z_ > 0) {
    // Along z with the z-pencil's strides: contiguous lines where z is split (z fastest),
    // strided across the x-fastest block where it is whole.
    fftw_iodim len{NZ, 0, 0}, loops[2];
    int nloops = 0;
    std::int64_t stride = 1;
    for (int q = 0; q < 3; ++q) {
      const int axis = l2.ord[q];
      const int n = static_cast<int>(l2.ext(axis)), st = static_cast<int>(stride);
      if (axis == Z) len.is = len.os = st;
      else loops[nloops++] = fftw_iodim{n, st, st};
      stride *= l2.ext(axis);
    }
    auto* c = reinterpret_cast<fftw_complex*>(p2_);
    plan_zf_ = fftw_plan_guru_dft(1, &len, nloops, loops, c, c, FFTW_FORWARD, flags);
    plan_zb_ = fftw_plan_guru_dft(1, &len, nloops, loops, c, c, FFTW_BACKWARD, flags);
  }
  if ((lines_x_ > 0 && (!plan_r2c_ || !plan_c2r_)) || (lines_z_ > 0 && (!plan_zf_ || !plan_zb_)))
    throw ConfigError("FftPoisson: FFTW could not make a plan");

  constexpr double pi = std::numbers::pi;
  lam_x_.resize(MX);
  for (int k = 0; k < MX; ++k) {
    const double s = std::sin(pi * k / NX);
    lam_x_[k] = -4.0 * inv_h2_[X] * s * s;
  }
  lam_z_.resize(NZ);
  for (int k = 0; k < NZ; ++k) {
    const double s = std::sin(pi * k / NZ);
    lam_z_[k] = -4.0 * inv_h2_[Z] * s * s;
  }

  // The y-pencil as [outer][y][lane]: the axes stored before y are the lanes.
  int yq = 0;
  while (l3.ord[yq] != Y) ++yq;
  lanes_ = 1, outer_ = 1;
  for (int q = 0; q < 3; ++q) (q < yq ? lanes_ : outer_) *= (q == yq ? 1 : l3.ext(l3.ord[q]));
  lam_lane_.assign(static_cast<std::size_t>(lanes_ * outer_), 0.0);
  Layout bottom = l3;
  bottom.hi[Y] = bottom.lo[Y] + 1;
  for_each_point(bottom, [&](const Int3& g) {
    const std::int64_t p = l3.pos(g), o = p / (lanes_ * NY), m = p % (lanes_ * NY);
    lam_lane_[static_cast<std::size_t>(o * lanes_ + m)] = lam_x_[g[X]] + lam_z_[g[Z]];
    if (g[X] == 0 && g[Z] == 0) singular_ = p;
  });
}

FftPoisson::~FftPoisson() {
  for (void* p : {plan_r2c_, plan_c2r_, plan_zf_, plan_zb_})
    if (p) fftw_destroy_plan(static_cast<fftw_plan>(p));
  for (MPI_Comm* c : {&comm_x_, &comm_z_, &comm_xy_})
    if (*c != MPI_COMM_NULL) MPI_Comm_free(c);
}

std::int64_t FftPoisson::doubles_sent() const {
  std::int64_t s = 0;
  for (const Transpose* t : {&t1_, &t2_, &t3_}) {
    int self = 0;
    MPI_Comm_rank(t->comm, &self);
    for (std::size_t p = 0; p < t->send_counts.size(); ++p)
      if (static_cast<int>(p) != self) s += t->send_counts[p] + t->recv_counts[p];
  }
  return s;
}

void FftPoisson::solve(const Field& rhs, Field& x, double factor) {
  if (rhs.stagger() != Stagger::cell || x.stagger() != Stagger::cell || rhs.n() != n_local_ || x.n() != n_local_)
    throw ConfigError("FftPoisson::solve: rhs and x must be cell-centred fields of the solver's decomposition");
  const int nx = n_local_[X], ny = n_local_[Y], nz = n_local_[Z];
  const int NX = n_global_[X], NY = n_global_[Y], NZ = n_global_[Z];
  const double start = MPI_Wtime();
  for (Transpose* t : {&t1_, &t2_, &t3_}) t->mpi_seconds = 0.0;

  double* b0 = p0_;
#pragma omp parallel for collapse(2) schedule(static)
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      std::memcpy(b0 + nx * (j + std::int64_t{ny} * k), rhs.data() + rhs.index(0, j, k), sizeof(double) * nx);

  // Forward: x-pencil, r2c along x; z-pencil, c2c along z; y-pencil.
  t1_.forward(b0, p1_);
  if (plan_r2c_) fftw_execute(static_cast<fftw_plan>(plan_r2c_));
  t2_.forward(p1c_, p2_);
  if (plan_zf_) fftw_execute(static_cast<fftw_plan>(plan_zf_));
  t3_.forward(p2_, p3_);

  // Tridiagonal solves along y, vectorised across a chunk of lanes at a time.  The
  // 1/(NX NZ) of the unnormalised inverse transforms and the caller's factor are folded in.
  {
    using C = std::complex<double>;
    C* b3 = reinterpret_cast<C*>(p3_);
    const double scale = factor / (double(NX) * NZ);
    const double a = inv_h2_[Y];
    const double dy2 = 1.0 / a;
    const std::int64_t lanes = lanes_, outer = outer_, plane = lanes_ * NY;
    const double* lam_all = lam_lane_.data();
    // The (0, 0) mode is singular: its rhs kept aside, its lane solved apart below.
    std::vector<C> r0;
    if (singular_ >= 0)
      for (int j = 0; j < NY; ++j) r0.push_back(b3[singular_ + j * lanes]);
    if (NY == 1) {
      for (std::int64_t p = 0; p < lanes * outer; ++p) b3[p] = b3[p] * scale / lam_all[p];
    } else {
#pragma omp parallel
      {
        constexpr int kChunk = 64;
        std::vector<double> cp(static_cast<std::size_t>(kChunk) * NY);
        std::vector<C> dp(static_cast<std::size_t>(kChunk) * NY);
#pragma omp for collapse(2) schedule(static)
        for (std::int64_t o = 0; o < outer; ++o)
          for (std::int64_t c0 = 0; c0 < lanes; c0 += kChunk) {
            const int w = static_cast<int>(std::min<std::int64_t>(kChunk, lanes - c0));
            C* line = b3 + o * plane + c0;
            const double* lam = lam_all + o * lanes + c0;
            // Rows: a x_{j-1} + b_j x_j + a x_{j+1} = r_j; wall rows b = -a + lam.
#pragma omp simd
            for (int m = 0; m < w; ++m) {
              const double b = -a + lam[m];
              cp[m] = a / b;
              dp[m] = line[m] * scale / b;
            }
            for (int j = 1; j < NY; ++j) {
              const double bw = j == NY - 1 ? -a : -2 * a;
              const double* cq = cp.data() + (j - 1) * kChunk;
              const C* dq = dp.data() + (j - 1) * kChunk;
              double* cj = cp.data() + j * kChunk;
              C* dj = dp.data() + j * kChunk;
              const C* r = line + j * lanes;
#pragma omp simd
              for (int m = 0; m < w; ++m) {
                const double bj = bw + lam[m];
                const double mm = bj - a * cq[m];
                cj[m] = a / mm;
                dj[m] = (r[m] * scale - a * dq[m]) / mm;
              }
            }
            for (int m = 0; m < w; ++m) line[(NY - 1) * lanes + m] = dp[(NY - 1) * kChunk + m];
            for (int j = NY - 2; j >= 0; --j) {
              const double* cj = cp.data() + j * kChunk;
              const C* dj = dp.data() + j * kChunk;
              C* xj = line + j * lanes;
              const C* up = xj + lanes;
#pragma omp simd
              for (int m = 0; m < w; ++m) xj[m] = dj[m] - cj[m] * up[m];
            }
          }
      }
    }
    if (singular_ >= 0) {
      // Remove the mean of the rhs (compatibility), integrate the flux from the bottom
      // wall, x_{j+1} - x_j = dy^2 sum_{i<=j} r_i, then zero mean.
      C mean = 0;
      for (int j = 0; j < NY; ++j) mean += r0[j];
      mean /= double(NY);
      C s = 0, v = 0, sum = 0;
      for (int j = 0; j < NY; ++j) {
        const C r = (r0[j] - mean) * scale;
        r0[j] = v;
        sum += v;
        s += r;
        v += dy2 * s;
      }
      const C vm = sum / double(NY);
      for (int j = 0; j < NY; ++j) b3[singular_ + j * lanes] = r0[j] - vm;
    }
  }

  // Backward.
  t3_.backward(p3_, p2_);
  if (plan_zb_) fftw_execute(static_cast<fftw_plan>(plan_zb_));
  t2_.backward(p2_, p1c_);
  if (plan_c2r_) fftw_execute(static_cast<fftw_plan>(plan_c2r_));
  t1_.backward(p1_, b0);

#pragma omp parallel for collapse(2) schedule(static)
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      std::memcpy(&x(0, j, k), b0 + nx * (j + std::int64_t{ny} * k), sizeof(double) * nx);

  if (timers_) {
    const double mpi = t1_.mpi_seconds + t2_.mpi_seconds + t3_.mpi_seconds;
    timers_->add(kTransposeRegion, mpi);
    timers_->add(kFftSolveRegion, MPI_Wtime() - start - mpi);
  }
}

}  // namespace efsi
