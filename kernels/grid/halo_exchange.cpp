#include "halo_exchange.hpp"

#include <algorithm>
#include <climits>
#include <cstring>
#include <stdexcept>

#include "compute_model.hpp"
#include "config_error.hpp"

namespace efsi {
namespace {

// A copy list the loops read: trimmed to its size, or, in the simulation build, where no
// loop reads it, given back.
template <class T>
void release_if_simulated(std::vector<T>& runs) {
  if constexpr (kSimulated) std::vector<T>().swap(runs);
  else runs.shrink_to_fit();
}

// A value a halo copy moves: read once, written once (work_count.hpp); what the simulation
// build charges for packing, unpacking, self-copies and walls.
constexpr PerCell kCopiedValue{16, 0};

// x-face runs are only halo-wide (1 to 3 values): a call to memcpy per run would cost
// more than the copy itself.  The lengths are constants: GCC turns a copy loop of run-time
// length into a call to memmove, short or not (measured: the x faces of the state exchange
// on one rank took 0.88 ms of its 1.23, the z faces with the same bytes 0.13).
template <int L>
inline void copy_fixed(double* __restrict dst, const double* __restrict src) {
  for (int i = 0; i < L; ++i) dst[i] = src[i];
}
inline void copy_run(double* __restrict dst, const double* __restrict src, int len) {
  switch (len) {
    case 1: copy_fixed<1>(dst, src); return;
    case 2: copy_fixed<2>(dst, src); return;
    case 3: copy_fixed<3>(dst, src); return;
    case 4: copy_fixed<4>(dst, src); return;
    default: std::memcpy(dst, src, sizeof(double) * static_cast<std::size_t>(len));
  }
}

template <bool kToBuffer>
inline void copy_block(double* field, double* buf, int len, int rows, std::ptrdiff_t stride) {
  for (int m = 0; m < rows; ++m, field += stride, buf += len) {
    if constexpr (kToBuffer) copy_run(buf, field, len);
    else copy_run(field, buf, len);
  }
}

Int3 step_of(int d) { return {d % 3 - 1, (d / 3) % 3 - 1, d / 9 - 1}; }
int opposite(int d) { return 26 - d; }
// Whether direction d steps across the faces of `axis` (none for axis -1).
bool crosses(int d, int axis) { return axis >= 0 && step_of(d)[axis] != 0; }

// The extent along `a` of the boxes of a direction: a step along it takes the boundary
// planes (send) or the ghosts beyond them (receive); no step takes the owned points, or,
// `wide`, the owned points and the ghosts on each side that has a neighbour (a phased round
// after the round of `a`: those ghosts are current and travel on to the corners).
struct Extent {
  bool wide = false;
  bool below = false, above = false;  // a neighbour on that side (wide only)
};

Box direction_box(const Field& f, const Int3& s, const std::array<Extent, 3>& ext, bool send) {
  Box b;
  const int h = f.halo();
  for (int a = 0; a < 3; ++a) {
    const int n = f.n()[a];
    if (s[a] == 0) {
      b.lo[a] = ext[a].wide && ext[a].below ? -h : 0;
      b.hi[a] = ext[a].wide && ext[a].above ? n + h : f.owned_end(a);
    } else if (s[a] > 0) {
      b.lo[a] = send ? n - h : n, b.hi[a] = send ? n : n + h;
    } else {
      b.lo[a] = send ? 0 : -h, b.hi[a] = send ? h : 0;
    }
  }
  return b;
}

}  // namespace

HaloExchange::HaloExchange(const CartDecomposition& decomp, std::vector<Field*> fields, Reach reach,
                           RegionTimers* timers, std::array<bool, 3> axes)
    : fields_(std::move(fields)),
      reach_(reach),
      axes_(axes),
      timers_(timers),
      self_(decomp.rank()),
      comm_(decomp.comm()) {
  for (const Field* f : fields_) {
    if (f->n() != decomp.local() || f->offset() != decomp.offset())
      throw std::invalid_argument("HaloExchange: field " + f->name() + " belongs to another decomposition");
  }
  build_runs(decomp);
  build_walls(decomp);
  requests_.reserve(2 * kDirs);
}

void HaloExchange::build_runs(const CartDecomposition& decomp) {
  const bool phased = reach_ == Reach::full_phased;
  if (phased) {
    rounds_ = 0;
    for (int a = 0; a < 3; ++a)
      if (axes_[a]) round_of_axis_[a] = rounds_++;
    rounds_ = std::max(rounds_, 1);
  }
  std::size_t send_total = 0, recv_total = 0;
  for (int d = 0; d < kDirs; ++d) {
    peer_[d] = MPI_PROC_NULL;
    if (d == kSelf) continue;
    const Int3 s = step_of(d);
    const int nonzero = (s[0] != 0) + (s[1] != 0) + (s[2] != 0);
    if (reach_ != Reach::full && nonzero > 1) continue;
    if ((s[0] != 0 && !axes_[0]) || (s[1] != 0 && !axes_[1]) || (s[2] != 0 && !axes_[2])) continue;
    // A direction and its opposite travel in one round, a wall's side included: the sync
    // form pairs each send with the receive from the opposite side.
    const int axis = s[0] != 0 ? 0 : s[1] != 0 ? 1 : 2;
    if (phased) round_of_dir_[d] = round_of_axis_[axis];
    peer_[d] = decomp.neighbour(s);
    if (peer_[d] == MPI_PROC_NULL) continue;
    // Phased: the axes of earlier rounds are taken wide.
    std::array<Extent, 3> ext{};
    if (phased) {
      for (int b = 0; b < 3; ++b)
        if (b != axis && round_of_axis_[b] >= 0 && round_of_axis_[b] < round_of_axis_[axis]) {
          Int3 down{0, 0, 0}, up{0, 0, 0};
          down[b] = -1, up[b] = 1;
          ext[b] = {true, decomp.neighbour(down) != MPI_PROC_NULL, decomp.neighbour(up) != MPI_PROC_NULL};
        }
    }
    const int r = round_of_dir_[d];

    send_off_[d] = send_total;
    recv_off_[d] = recv_total;
    for (int fi = 0; fi < static_cast<int>(fields_.size()); ++fi) {
      const Field& f = *fields_[fi];
      const Box in = direction_box(f, s, ext, false);
      const int len = in.hi[X] - in.lo[X], rows = in.hi[Y] - in.lo[Y];
      if (peer_[d] == self_) {
        // This rank's own points across the box: what its opposite face sends.
        const Box out = direction_box(f, {-s[0], -s[1], -s[2]}, ext, true);
        for (int k = in.lo[Z], ks = out.lo[Z]; k < in.hi[Z]; ++k, ++ks)
          self_runs_[r].push_back(
              SelfRun{fi, len, rows, f.index(out.lo[X], out.lo[Y], ks), f.index(in.lo[X], in.lo[Y], k), f.stride_y()});
        const std::size_t n = static_cast<std::size_t>(len) * rows * (in.hi[Z] - in.lo[Z]);
        send_total += n, recv_total += n;  // counted, never buffered
        continue;
      }
      auto add_runs = [&](const Box& b, std::vector<Run>& runs, std::size_t& total) {
        const int blen = b.hi[X] - b.lo[X], brows = b.hi[Y] - b.lo[Y];
        for (int k = b.lo[Z]; k < b.hi[Z]; ++k) {
          runs.push_back(Run{d, fi, blen, brows, f.index(b.lo[X], b.lo[Y], k), f.stride_y(), total});
          total += static_cast<std::size_t>(blen) * static_cast<std::size_t>(brows);
        }
      };
      add_runs(direction_box(f, s, ext, true), send_runs_[r], send_total);
      add_runs(in, recv_runs_[r], recv_total);
    }
    send_count_[d] = send_total - send_off_[d];
    recv_count_[d] = recv_total - recv_off_[d];
    if (peer_[d] == self_) send_total = send_off_[d], recv_total = recv_off_[d];
    if (send_count_[d] > static_cast<std::size_t>(INT_MAX))
      throw ConfigError("halo message of " + std::to_string(send_count_[d]) +
                        " values exceeds the MPI count limit " + std::to_string(INT_MAX));
  }
  for (int d = 0; d < kDirs; ++d) {
    if (peer_[d] == MPI_PROC_NULL) continue;
    if (peer_[d] == self_) {
      if (recv_count_[d] != send_count_[opposite(d)])
        throw std::logic_error("HaloExchange: self-copy sizes differ");
      local_doubles_ += send_count_[d];
      round_local_doubles_[round_of_dir_[d]] += send_count_[d];
    } else {
      mpi_doubles_ += send_count_[d];
      round_mpi_doubles_[round_of_dir_[d]] += send_count_[d];
      ++mpi_messages_;
      for (int a = 0; a < 3; ++a)
        if (crosses(d, a)) across_doubles_[a] += recv_count_[d];
    }
  }
  // Field by field, plane by plane: the two x-face runs of a row touch the same cache lines
  // at its two ends (ghosts beside the owned points they copy from the other end), so run
  // one after the other they bring those lines from memory once instead of twice.  Sources
  // are owned points (or ghosts of an earlier round) and destinations ghosts of this round,
  // so the order moves no value.
  for (auto& runs : self_runs_)
    std::sort(runs.begin(), runs.end(), [](const SelfRun& a, const SelfRun& b) {
      return a.field != b.field ? a.field < b.field : a.dst < b.dst;
    });
  // Kept for the whole run by every rank, so the simulation build, whose copies never run
  // (compute_model.hpp), keeps the counts alone: it holds 8192 ranks' lists in one process,
  // a run per plane, field and direction, 1.1 MB a rank of 64^3 over its exchanges.
  for (int r = 0; r < kMaxRounds; ++r) {
    release_if_simulated(send_runs_[r]);
    release_if_simulated(recv_runs_[r]);
    release_if_simulated(self_runs_[r]);
  }
  send_buf_ = allocate_storage(send_total, true);
  recv_buf_ = allocate_storage(recv_total, true);
}

void HaloExchange::build_walls(const CartDecomposition& decomp) {
  if (!axes_[Y]) return;
  for (int fi = 0; fi < static_cast<int>(fields_.size()); ++fi) {
    const Field& f = *fields_[fi];
    const int h = f.halo();
    const int ny = f.n()[Y];
    const bool face = is_staggered(f.stagger(), Y);
    const double sign = f.spec().parity == WallParity::odd ? -1.0 : 1.0;
    // Ghost columns next to the wall are mirrored too when the exchange filled them.
    const bool all = reach_ != Reach::faces;
    const int ilo = all ? -h : 0, ihi = f.n()[X] + (all ? h : 0);
    const int klo = all ? -h : 0, khi = f.n()[Z] + (all ? h : 0);
    auto rows = [&](std::vector<WallRun>& out, int jdst, int jsrc, double sg) {
      for (int k = klo; k < khi; ++k)
        out.push_back(WallRun{fi, f.index(ilo, jdst, k), f.index(ilo, jsrc, k), ihi - ilo, sg});
    };
    // The wall face itself is zeroed across the whole plane, ghosts included: a neighbour
    // may have sent its copy of the face before its own wall rule ran.
    auto zero_plane = [&](int j) {
      for (int k = -h; k < f.n()[Z] + h; ++k)
        wall_zero_.push_back(WallRun{fi, f.index(-h, j, k), f.index(-h, j, k), f.n()[X] + 2 * h, 0.0});
    };
    const bool odd_face = face && f.spec().parity == WallParity::odd;
    if (decomp.wall_below()) {
      if (odd_face) zero_plane(0);
      for (int m = 0; m < h; ++m) {
        if (face) rows(wall_mirror_, -1 - m, 1 + m, sign);  // about the wall face j = 0
        else rows(wall_mirror_, -1 - m, m, sign);           // about y = 0, between cells -1 and 0
      }
    }
    if (decomp.wall_above()) {
      if (odd_face) zero_plane(ny);
      for (int m = 0; m < h; ++m) {
        if (face) {
          if (m + 1 < h) rows(wall_mirror_, ny + 1 + m, ny - 1 - m, sign);  // about the wall face j = ny
        } else {
          rows(wall_mirror_, ny + m, ny - 1 - m, sign);
        }
      }
    }
  }
  for (auto* runs : {&wall_zero_, &wall_mirror_}) {
    for (const WallRun& w : *runs) wall_doubles_ += static_cast<std::size_t>(w.len);
    release_if_simulated(*runs);
  }
}

void HaloExchange::pack(int r) {
  const std::vector<Run>& runs = send_runs_[r];
  const std::size_t nr = runs.size();
  double* buf = send_buf_.get();
  Field* const* f = fields_.data();
  compute_stage(kCopiedValue, double(round_mpi_doubles_[r]), [&] {
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < nr; ++i) {
      const Run& run = runs[i];
      copy_block<true>(f[run.field]->data() + run.index, buf + run.buf, run.len, run.rows, run.stride);
    }
  });
}

void HaloExchange::copy_self(int r) {
  const std::vector<SelfRun>& runs = self_runs_[r];
  const std::size_t nr = runs.size();
  Field* const* f = fields_.data();
  compute_stage(kCopiedValue, double(round_local_doubles_[r]), [&] {
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < nr; ++i) {
      const SelfRun& run = runs[i];
      double* base = f[run.field]->data();
      const double* src = base + run.src;
      double* dst = base + run.dst;
      for (int m = 0; m < run.rows; ++m, src += run.stride, dst += run.stride) copy_run(dst, src, run.len);
    }
  });
}

void HaloExchange::unpack(int r, bool walls) {
  RegionTimers::Scope t(timers_, Region::halo_unpack);
  Field* const* f = fields_.data();
  double* buf = recv_buf_.get();
  const std::vector<Run>& runs = recv_runs_[r];
  const std::size_t nr = runs.size();
  const std::size_t nz = walls ? wall_zero_.size() : 0, nm = walls ? wall_mirror_.size() : 0;
  const std::size_t unpacked =
      round_mpi_doubles_[r] - (finished_across_ >= 0 ? across_doubles_[finished_across_] : 0);
  compute_stage(kCopiedValue, double(unpacked + (walls ? wall_doubles_ : 0)), [&] {
#pragma omp parallel
    {
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < nr; ++i) {
        const Run& run = runs[i];
        if (crosses(run.dir, finished_across_)) continue;  // unpacked by finish_across
        copy_block<false>(f[run.field]->data() + run.index, buf + run.buf, run.len, run.rows, run.stride);
      }
      // Wall faces are zeroed before the mirrors read them (a one-rank-high grid mirrors
      // the bottom ghosts from the top wall face).  Phased, they run after the last round:
      // the z round may have brought a neighbour's wall ghosts before its wall rule ran.
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < nz; ++i) {
        const WallRun& w = wall_zero_[i];
        double* d = f[w.field]->data() + w.dst;
        for (int m = 0; m < w.len; ++m) d[m] = 0.0;
      }
#pragma omp for schedule(static)
      for (std::size_t i = 0; i < nm; ++i) {
        const WallRun& w = wall_mirror_[i];
        double* base = f[w.field]->data();
        for (int m = 0; m < w.len; ++m) base[w.dst + m] = w.sign * base[w.src + m];
      }
    }
  });
}

void HaloExchange::exchange() {
  if (in_flight_) throw std::logic_error("HaloExchange::exchange while an async exchange is in flight");
  for (int r = 0; r < rounds_; ++r) {
    {
      RegionTimers::Scope t(timers_, Region::halo_pack);
      pack(r);
      copy_self(r);
    }
    {
      RegionTimers::Scope t(timers_, Region::halo_mpi);
      for (int d = 0; d < kDirs; ++d) {
        if (d == kSelf || round_of_dir_[d] != r) continue;
        const int back = opposite(d);
        const int dest = peer_[d] == self_ ? MPI_PROC_NULL : peer_[d];
        const int src = peer_[back] == self_ ? MPI_PROC_NULL : peer_[back];
        if (dest == MPI_PROC_NULL && src == MPI_PROC_NULL) continue;
        // Tag = direction of travel as the sender sees it.
        MPI_Sendrecv(send_buf_.get() + send_off_[d], static_cast<int>(send_count_[d]), MPI_DOUBLE, dest, d,
                     recv_buf_.get() + recv_off_[back], static_cast<int>(recv_count_[back]), MPI_DOUBLE, src, d,
                     comm_, MPI_STATUS_IGNORE);
      }
    }
    unpack(r, r + 1 == rounds_);
  }
}

void HaloExchange::start_round(int r) {
  round_ = r;
  requests_.clear();
  for (int d = 0; d < kDirs; ++d) recv_request_[d] = -1;
  {
    RegionTimers::Scope t(timers_, Region::halo_mpi);
    for (int d = 0; d < kDirs; ++d) {
      if (peer_[d] == MPI_PROC_NULL || peer_[d] == self_ || round_of_dir_[d] != r) continue;
      recv_request_[d] = static_cast<int>(requests_.size());
      requests_.emplace_back();
      MPI_Irecv(recv_buf_.get() + recv_off_[d], static_cast<int>(recv_count_[d]), MPI_DOUBLE, peer_[d],
                opposite(d), comm_, &requests_.back());
    }
  }
  {
    RegionTimers::Scope t(timers_, Region::halo_pack);
    pack(r);
    copy_self(r);
  }
  RegionTimers::Scope t(timers_, Region::halo_mpi);
  for (int d = 0; d < kDirs; ++d) {
    if (peer_[d] == MPI_PROC_NULL || peer_[d] == self_ || round_of_dir_[d] != r) continue;
    requests_.emplace_back();
    MPI_Isend(send_buf_.get() + send_off_[d], static_cast<int>(send_count_[d]), MPI_DOUBLE, peer_[d], d, comm_,
              &requests_.back());
  }
}

void HaloExchange::complete_round() {
  {
    RegionTimers::Scope t(timers_, Region::halo_wait);
    MPI_Waitall(static_cast<int>(requests_.size()), requests_.data(), MPI_STATUSES_IGNORE);
  }
  const bool last = round_ + 1 == rounds_;
  unpack(round_, last);
  if (last) round_ = rounds_;
  else start_round(round_ + 1);
}

void HaloExchange::begin() {
  if (in_flight_) throw std::logic_error("HaloExchange::begin twice without finish");
  in_flight_ = true;
  start_round(0);
}

void HaloExchange::progress() {
  if (!in_flight_ || round_ >= rounds_) return;
  // SMPI moves messages without MPI calls, so a test there changes no simulated time; it
  // only costs the simulator: SimGrid 3.32 keeps every comm MPI_Testall looked at on the
  // rank's activity list, which each later compute charge walks (async SOR, 8 ranks, 160
  // sweeps: 15 s of simulator time against 2 s, the same simulated time to the last
  // digit).  Only a round that lets the next go needs to know it has arrived.
  if constexpr (kSimulated)
    if (round_ + 1 >= rounds_) return;
  int done = 1;
  if (!requests_.empty()) {
    RegionTimers::Scope t(timers_, Region::halo_mpi);
    MPI_Testall(static_cast<int>(requests_.size()), requests_.data(), &done, MPI_STATUSES_IGNORE);
  }
  // A round that has arrived lets the next one go; the last waits for finish().
  if (done && round_ + 1 < rounds_) complete_round();
}

void HaloExchange::finish() {
  if (!in_flight_) throw std::logic_error("HaloExchange::finish without begin");
  while (round_ < rounds_) complete_round();
  in_flight_ = false;
  finished_across_ = -1;
}

void HaloExchange::finish_across(int axis) {
  if (!in_flight_) throw std::logic_error("HaloExchange::finish_across without begin");
  if (reach_ == Reach::full_phased) {
    while (round_ <= round_of_axis_[axis] && round_ < rounds_) complete_round();
    return;
  }
  {
    RegionTimers::Scope t(timers_, Region::halo_wait);
    for (int d = 0; d < kDirs; ++d)
      if (crosses(d, axis) && recv_request_[d] >= 0)
        MPI_Wait(&requests_[static_cast<std::size_t>(recv_request_[d])], MPI_STATUS_IGNORE);
  }
  RegionTimers::Scope t(timers_, Region::halo_unpack);
  Field* const* f = fields_.data();
  double* buf = recv_buf_.get();
  const std::vector<Run>& runs = recv_runs_[0];
  const std::size_t nr = runs.size();
  compute_stage(kCopiedValue, double(across_doubles_[axis]), [&] {
#pragma omp parallel for schedule(static)
    for (std::size_t i = 0; i < nr; ++i) {
      const Run& run = runs[i];
      if (!crosses(run.dir, axis)) continue;
      copy_block<false>(f[run.field]->data() + run.index, buf + run.buf, run.len, run.rows, run.stride);
    }
  });
  finished_across_ = axis;
}

}  // namespace efsi
