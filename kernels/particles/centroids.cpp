#include "centroids.hpp"

#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

namespace efsi {
namespace {

using Shift = std::array<std::int64_t, 3>;  // periodic images crossed, per axis

// Union-find whose links carry the image shift between a node and its parent, so that
// joining pieces across the periodic seam also tells how to unwrap them: image(a) =
// image(root) + shift of a.  A link that closes a loop with a non-zero net shift means
// the set touches its own periodic image along that axis.  Roots are always the smallest
// node of their set, which makes the labels independent of the order of the unions.
// Off is the stored per-link shift type: 32 bits suffice within a rank's block (a link
// never crosses more seams than the block has cells) and keep the dense forest small.
template <class Index, class Off>
class ImageUnionFind {
 public:
  explicit ImageUnionFind(std::size_t n) : parent_(n, -1), shift_(n), wraps_(n, 0) {}

  void make(Index a) { parent_[a] = a; }
  bool contains(Index a) const { return parent_[a] >= 0; }

  Index find(Index a, Shift& s) {
    Index r = a;
    Shift total{0, 0, 0};
    while (parent_[r] != r) {
      for (int ax = 0; ax < 3; ++ax) total[ax] += shift_[r][ax];
      r = parent_[r];
    }
    // Path compression: point every node on the way straight at the root.
    Shift rest = total;
    for (Index x = a; parent_[x] != x;) {
      const Index next = parent_[x];
      const std::array<Off, 3> own = shift_[x];
      parent_[x] = r;
      for (int ax = 0; ax < 3; ++ax) shift_[x][ax] = static_cast<Off>(rest[ax]);
      for (int ax = 0; ax < 3; ++ax) rest[ax] -= own[ax];
      x = next;
    }
    s = total;
    return r;
  }

  // Records image(b) = image(a) + d.
  void unite(Index a, Index b, const Shift& d) {
    Shift sa{}, sb{};
    const Index ra = find(a, sa), rb = find(b, sb);
    if (ra == rb) {
      for (int ax = 0; ax < 3; ++ax)
        if (sb[ax] - sa[ax] != d[ax]) wraps_[ra] |= std::uint8_t(1u << ax);
      return;
    }
    // image(rb) - image(ra) = sa + d - sb
    Shift rel{};
    for (int ax = 0; ax < 3; ++ax) rel[ax] = sa[ax] + d[ax] - sb[ax];
    if (ra < rb) {
      link(rb, ra, rel);
    } else {
      for (int ax = 0; ax < 3; ++ax) rel[ax] = -rel[ax];
      link(ra, rb, rel);
    }
  }

  void add_wraps(Index root, std::uint8_t bits) { wraps_[root] |= bits; }
  std::uint8_t wraps(Index root) const { return wraps_[root]; }

 private:
  void link(Index child, Index root, const Shift& rel) {
    parent_[child] = root;
    for (int ax = 0; ax < 3; ++ax) shift_[child][ax] = static_cast<Off>(rel[ax]);
    wraps_[root] |= wraps_[child];
  }

  std::vector<Index> parent_;
  std::vector<std::array<Off, 3>> shift_;
  std::vector<std::uint8_t> wraps_;
};

// One connected piece of a region on one rank, in the frame of its root cell (the
// piece's lowest cell, placed in the box).
struct Piece {
  std::int64_t id = 0;    // global linear index of the root cell
  Int3 root{};            // its global cell index
  std::int64_t cells = 0;
  std::uint8_t wraps = 0;
  double phi = 0.0;                      // sum of phi
  std::array<double, 3> moment{};        // sum of phi * (unwrapped cell - root cell), in cells
  std::array<double, 3> wrapped{};       // sum of phi * in-box cell centre, in cells
};

// A contact between two pieces on either side of a rank boundary: image(b) = image(a) + d.
struct Contact {
  std::int64_t a, b;
  Shift d;
  auto key() const { return std::tie(a, b, d); }
};

constexpr int kPieceInts = 6, kPieceDoubles = 7, kContactInts = 5, kRegionInts = 3, kRegionDoubles = 4;

// Concatenates every rank's `mine` on rank 0, in rank order (empty elsewhere).
template <class T>
std::vector<T> gather_on_root(const std::vector<T>& mine, MPI_Datatype type, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const int count = static_cast<int>(mine.size());
  std::vector<int> counts(rank == 0 ? size : 0), displs;
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  std::vector<T> all;
  if (rank == 0) {
    displs.resize(size);
    long long total = 0;
    for (int r = 0; r < size; ++r) {
      displs[r] = static_cast<int>(total);
      total += counts[r];
      if (total > std::numeric_limits<int>::max()) {
        // Only rank 0 knows, and the others already wait in the gather: stop everyone.
        std::fprintf(stderr, "solid_regions: more than 2^31 values to gather on rank 0\n");
        MPI_Abort(comm, 1);
      }
    }
    all.resize(static_cast<std::size_t>(total));
  }
  MPI_Gatherv(mine.data(), count, type, all.data(), counts.data(), displs.data(), type, 0, comm);
  return all;
}

}  // namespace

std::vector<SolidRegion> solid_regions(const Field& phi, const Domain& domain, const CartDecomposition& decomp) {
  const Int3 n = decomp.local(), off = decomp.offset(), N = decomp.global(), dims = decomp.dims(),
             coords = decomp.coords();
  if (phi.stagger() != Stagger::cell || phi.n() != n || phi.offset() != off)
    throw std::invalid_argument("solid_regions: " + phi.name() + " is not a cell-centred field of this decomposition");
  const std::int64_t ncells = product(n);
  if (ncells > std::numeric_limits<std::int32_t>::max())
    throw std::invalid_argument("solid_regions: local block " + to_string(n) + " has more than 2^31 cells");
  const MPI_Comm comm = decomp.comm();

  // 1. Local labelling.  32-bit indices halve the memory of the (dense) forest.
  using Local = std::int32_t;
  const auto lin = [&](int i, int j, int k) {
    return static_cast<Local>(i + std::int64_t{n[X]} * (j + std::int64_t{n[Y]} * k));
  };
  ImageUnionFind<Local, std::int32_t> uf(static_cast<std::size_t>(ncells));
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) {
        if (!(phi(i, j, k) > 0.5)) continue;
        const Local c = lin(i, j, k);
        uf.make(c);
        if (i > 0 && uf.contains(lin(i - 1, j, k))) uf.unite(lin(i - 1, j, k), c, {0, 0, 0});
        if (j > 0 && uf.contains(lin(i, j - 1, k))) uf.unite(lin(i, j - 1, k), c, {0, 0, 0});
        if (k > 0 && uf.contains(lin(i, j, k - 1))) uf.unite(lin(i, j, k - 1), c, {0, 0, 0});
      }
  // A rank that spans a whole periodic axis is its own neighbour there: join across the
  // seam here, one image further on.
  if (dims[X] == 1)
    for (int k = 0; k < n[Z]; ++k)
      for (int j = 0; j < n[Y]; ++j)
        if (uf.contains(lin(n[X] - 1, j, k)) && uf.contains(lin(0, j, k)))
          uf.unite(lin(n[X] - 1, j, k), lin(0, j, k), {1, 0, 0});
  if (dims[Z] == 1)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i)
        if (uf.contains(lin(i, j, n[Z] - 1)) && uf.contains(lin(i, j, 0)))
          uf.unite(lin(i, j, n[Z] - 1), lin(i, j, 0), {0, 0, 1});

  // 2. Pieces: roots are the lowest cell of their set, so a root is met before the rest.
  std::vector<Piece> pieces;
  std::vector<std::int32_t> piece_of(static_cast<std::size_t>(ncells), -1);
  const auto global_id = [&](const Int3& g) {
    return g[X] + std::int64_t{N[X]} * (g[Y] + std::int64_t{N[Y]} * g[Z]);
  };
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) {
        const Local c = lin(i, j, k);
        if (!uf.contains(c)) continue;
        Shift s{};
        const Local r = uf.find(c, s);
        const Int3 g{off[X] + i, off[Y] + j, off[Z] + k};
        if (r == c) {
          piece_of[c] = static_cast<std::int32_t>(pieces.size());
          Piece p;
          p.id = global_id(g);
          p.root = g;
          p.wraps = uf.wraps(r);
          pieces.push_back(p);
        }
        Piece& p = pieces[piece_of[r]];
        const double w = phi(i, j, k);
        p.cells += 1;
        p.phi += w;
        for (int ax = 0; ax < 3; ++ax) {
          p.moment[ax] += w * double(g[ax] - p.root[ax] + s[ax] * N[ax]);
          p.wrapped[ax] += w * (g[ax] + 0.5);
        }
      }

  // 3. Contacts across rank boundaries: every rank sends its top plane along each split
  // axis to the next rank up and pairs the plane it receives with its own bottom plane.
  std::vector<Contact> contacts;
  for (int ax = 0; ax < 3; ++ax) {
    if (dims[ax] == 1) continue;
    const int b = (ax + 1) % 3, c = (ax + 2) % 3;
    const std::size_t plane = std::size_t(n[b]) * n[c];
    std::vector<std::int64_t> send(4 * plane, -1), recv(4 * plane, -1);
    const auto cell_at = [&](int along, int ub, int uc) {
      Int3 idx{};
      idx[ax] = along, idx[b] = ub, idx[c] = uc;
      return lin(idx[X], idx[Y], idx[Z]);
    };
    for (int uc = 0; uc < n[c]; ++uc)
      for (int ub = 0; ub < n[b]; ++ub) {
        const Local cell = cell_at(n[ax] - 1, ub, uc);
        if (!uf.contains(cell)) continue;
        Shift s{};
        const Local r = uf.find(cell, s);
        std::int64_t* q = &send[4 * (ub + std::size_t(n[b]) * uc)];
        q[0] = pieces[piece_of[r]].id, q[1] = s[0], q[2] = s[1], q[3] = s[2];
      }
    Int3 up{0, 0, 0}, down{0, 0, 0};
    up[ax] = 1, down[ax] = -1;
    // Across a wall the neighbour is MPI_PROC_NULL and recv keeps its "no solid" labels.
    MPI_Sendrecv(send.data(), static_cast<int>(send.size()), MPI_INT64_T, decomp.neighbour(up), 70 + ax, recv.data(),
                 static_cast<int>(recv.size()), MPI_INT64_T, decomp.neighbour(down), 70 + ax, comm, MPI_STATUS_IGNORE);
    // Coming up from the last rank of a periodic axis crosses the seam: one image on.
    const std::int64_t seam = (ax != Y && coords[ax] == 0) ? 1 : 0;
    for (int uc = 0; uc < n[c]; ++uc)
      for (int ub = 0; ub < n[b]; ++ub) {
        const std::int64_t* q = &recv[4 * (ub + std::size_t(n[b]) * uc)];
        const Local cell = cell_at(0, ub, uc);
        if (q[0] < 0 || !uf.contains(cell)) continue;
        Shift s{};
        const Local r = uf.find(cell, s);
        Contact k{q[0], pieces[piece_of[r]].id, {q[1] - s[0], q[2] - s[1], q[3] - s[2]}};
        k.d[ax] += seam;
        contacts.push_back(k);
      }
  }
  std::sort(contacts.begin(), contacts.end(), [](const Contact& x, const Contact& y) { return x.key() < y.key(); });
  contacts.erase(std::unique(contacts.begin(), contacts.end(),
                             [](const Contact& x, const Contact& y) { return x.key() == y.key(); }),
                 contacts.end());

  // 4. Rank 0 joins the pieces.
  std::vector<std::int64_t> piece_ints;
  std::vector<double> piece_doubles;
  for (const Piece& p : pieces) {
    piece_ints.insert(piece_ints.end(), {p.id, p.root[X], p.root[Y], p.root[Z], p.cells, std::int64_t{p.wraps}});
    piece_doubles.insert(piece_doubles.end(), {p.phi, p.moment[0], p.moment[1], p.moment[2], p.wrapped[0],
                                               p.wrapped[1], p.wrapped[2]});
  }
  std::vector<std::int64_t> contact_ints;
  for (const Contact& k : contacts) contact_ints.insert(contact_ints.end(), {k.a, k.b, k.d[0], k.d[1], k.d[2]});
  const auto all_ints = gather_on_root(piece_ints, MPI_INT64_T, comm);
  const auto all_doubles = gather_on_root(piece_doubles, MPI_DOUBLE, comm);
  const auto all_contacts = gather_on_root(contact_ints, MPI_INT64_T, comm);

  std::vector<std::int64_t> region_ints;
  std::vector<double> region_doubles;
  if (decomp.rank() == 0) {
    const std::size_t np = all_ints.size() / kPieceInts;
    // Nodes in id order, so the union-find's smallest-root rule makes every region's
    // root its lowest cell, and visiting nodes in order meets each root first.
    std::vector<std::size_t> order(np);
    for (std::size_t m = 0; m < np; ++m) order[m] = m;
    std::sort(order.begin(), order.end(),
              [&](std::size_t x, std::size_t y) { return all_ints[kPieceInts * x] < all_ints[kPieceInts * y]; });
    std::vector<std::int64_t> ids(np);
    for (std::size_t m = 0; m < np; ++m) ids[m] = all_ints[kPieceInts * order[m]];
    const auto node = [&](std::int64_t id) {
      return static_cast<std::int64_t>(std::lower_bound(ids.begin(), ids.end(), id) - ids.begin());
    };
    ImageUnionFind<std::int64_t, std::int64_t> g(np);
    for (std::size_t m = 0; m < np; ++m) g.make(static_cast<std::int64_t>(m));
    for (std::size_t e = 0; e + kContactInts <= all_contacts.size(); e += kContactInts)
      g.unite(node(all_contacts[e]), node(all_contacts[e + 1]),
              {all_contacts[e + 2], all_contacts[e + 3], all_contacts[e + 4]});
    for (std::size_t m = 0; m < np; ++m) {
      Shift s{};
      const auto bits = static_cast<std::uint8_t>(all_ints[kPieceInts * order[m] + 5]);
      g.add_wraps(g.find(static_cast<std::int64_t>(m), s), bits);
    }

    struct Sum {
      std::int64_t id, cells;
      Int3 root;
      double phi;
      std::array<double, 3> moment, wrapped;
    };
    std::vector<Sum> sums;
    std::vector<std::int64_t> sum_of(np, -1);
    for (std::size_t m = 0; m < np; ++m) {
      const std::int64_t* pi = &all_ints[kPieceInts * order[m]];
      const double* pd = &all_doubles[kPieceDoubles * order[m]];
      Shift s{};
      const auto r = static_cast<std::size_t>(g.find(static_cast<std::int64_t>(m), s));
      if (r == m) {
        sum_of[m] = static_cast<std::int64_t>(sums.size());
        sums.push_back({pi[0], 0, {int(pi[1]), int(pi[2]), int(pi[3])}, 0.0, {}, {}});
      }
      Sum& t = sums[sum_of[r]];
      t.cells += pi[4];
      t.phi += pd[0];
      for (int ax = 0; ax < 3; ++ax) {
        // The piece's own moment is about its root; move it to the region's root.
        const double root_offset = double(pi[1 + ax] - t.root[ax] + s[ax] * N[ax]);
        t.moment[ax] += pd[1 + ax] + pd[0] * root_offset;
        t.wrapped[ax] += pd[4 + ax];
      }
    }
    for (std::size_t m = 0; m < sums.size(); ++m) {
      const Sum& t = sums[m];
      const std::int64_t root_node = node(t.id);
      const std::uint8_t wraps = g.wraps(root_node);
      double cen[3];
      for (int ax = 0; ax < 3; ++ax) {
        double cells_pos;
        if (wraps & (1u << ax)) {
          cells_pos = t.wrapped[ax] / t.phi;
        } else {
          cells_pos = t.root[ax] + 0.5 + t.moment[ax] / t.phi;
          if (ax != Y) cells_pos -= N[ax] * std::floor(cells_pos / N[ax]);
        }
        cen[ax] = cells_pos * domain.spacing(ax);
      }
      region_ints.insert(region_ints.end(), {t.id, t.cells, std::int64_t{wraps}});
      region_doubles.insert(region_doubles.end(), {t.phi * domain.cell_volume(), cen[0], cen[1], cen[2]});
    }
  }

  // 5. Everyone gets the list.
  long long count = static_cast<long long>(region_ints.size() / kRegionInts);
  MPI_Bcast(&count, 1, MPI_LONG_LONG, 0, comm);
  region_ints.resize(static_cast<std::size_t>(count) * kRegionInts);
  region_doubles.resize(static_cast<std::size_t>(count) * kRegionDoubles);
  MPI_Bcast(region_ints.data(), static_cast<int>(region_ints.size()), MPI_INT64_T, 0, comm);
  MPI_Bcast(region_doubles.data(), static_cast<int>(region_doubles.size()), MPI_DOUBLE, 0, comm);

  std::vector<SolidRegion> out(static_cast<std::size_t>(count));
  for (std::size_t m = 0; m < out.size(); ++m) {
    const std::int64_t* ri = &region_ints[kRegionInts * m];
    const double* rd = &region_doubles[kRegionDoubles * m];
    out[m].volume = rd[0];
    out[m].centroid = {rd[1], rd[2], rd[3]};
    out[m].cells = ri[1];
    out[m].first_cell = ri[0];
    for (int ax = 0; ax < 3; ++ax) out[m].wraps[ax] = (ri[2] >> ax) & 1;
  }
  return out;
}

}  // namespace efsi
