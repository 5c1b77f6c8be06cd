#pragma once
// The governing equations (docs/numerics.md, "Governing equations" and "Spatial discretisation") in one place, shared by every
// pressure method: deviatoric stress, the unprojected velocity v* of eq. (6), and the
// WENO5 + upper-convected transport of phi and Bt. Each kernel works on a box of its
// output points, so a caller can do the interior while a halo exchange is in flight
// and the rest after it (the result is the same arithmetic either way).
#include <array>
#include <cstddef>
#include <memory>
#include <vector>

#include "fsi_state.hpp"
#include "rate_output.hpp"
#include "storage.hpp"

namespace efsi {

// Work arrays of one step.
struct FsiWork {
  FsiWork(const CartDecomposition& decomp);
  std::array<Field, 6> tau;    // deviatoric stress at tensor_location, tensor_index order
  std::array<Field, 3> vstar;  // unprojected velocity
  Field phi_new;
  std::array<Field, 6> B_new;
  Field div;  // rho div v* at cell centres (halo 1: the Laplacian reads neighbours)
  Field dp;   // pressure increment (halo 1: its gradient reads the low neighbour)
  Field root_phi;  // sqrt(max(phi, 0)) at cell centres, ghosts -1 included (solid_root)
};

// Output ranges of the kernels over the whole local block (ghost reads included) and
// over the part that reads no ghost a pending exchange has yet to fill.
struct KernelBoxes {
  Box stress_centres, stress_edges, momentum, transport;
};
KernelBoxes full_boxes(const Int3& n);
// The sides [axis][0: low, 1: high] whose ghosts are current while the exchange is in
// flight keep the full range: there a point may read its ghosts.  Every other side gives
// up the points that would read them.
using CurrentSides = std::array<std::array<bool, 2>, 3>;
KernelBoxes interior_boxes(const Int3& n, const CurrentSides& current = {});

// tau = 2 mu D + G sqrt(phi) (Bt - tr(Bt)/3 I): diagonal on `centres`, off-diagonal on `edges`.
// It first fills `root` = sqrt(max(phi, 0)) on the centres these points read, and leaves it
// there: the Crank-Nicolson sweeps of the same step reuse it (phi does not change in them).
void compute_stress(const FieldSet& s, const Physics& ph, Field& root, std::array<Field, 6>& tau,
                    const Box& centres, const Box& edges);

// The tendencies: each kernel computes a right-hand side d q / dt and writes it, or the
// explicit Euler update q + dt dq/dt of the integrator's stages (`out`, rate_output.hpp).

// dv/dt = (-grad p - rho v.grad v + div tau) / rho + f e_x on the faces of `faces` (zero on
// the wall faces of v, which stay at rest). Advection in the skew-symmetric form, which
// conserves kinetic energy for any velocity field.
void momentum_tendency(const FieldSet& s, const Physics& ph, const std::array<Field, 6>& tau,
                       std::array<Field, 3>& dvdt, const Box& faces, const RateOutput& out = {});

// The six stress components on a ring of three z-planes, each plane laid out as its Field's:
// ring[c](i, j, k) is plane k mod 3 of component c.  What the fused stress and momentum
// keep of tau instead of the whole arrays.
class TauRing {
 public:
  struct Planes {
    double* base;
    std::ptrdiff_t sy, sz;
    double& operator()(int i, int j, int k) const { return base[i + sy * j + sz * ((k + 3) % 3)]; }
  };
  explicit TauRing(const std::array<Field, 6>& layout);
  const Planes& operator[](int c) const { return planes_[c]; }
  Planes& operator[](int c) { return planes_[c]; }

 private:
  Storage data_;
  std::array<Planes, 6> planes_{};
};

// compute_stress then momentum_tendency over the whole block (full_boxes), fused plane by
// plane in z: each thread takes a range of planes and keeps tau on its own TauRing, so tau
// never goes to memory (written, read back: 144 B a cell), and the velocity a plane reads
// serves both while it is in cache.  The momentum comes out bitwise as from the two
// kernels; `root` is filled as compute_stress fills it, but the tau arrays are not, so a
// caller that reads them later (Crank-Nicolson) or splits the block into interior and
// shell (async) uses the two kernels instead.
class StressAndMomentum {
 public:
  explicit StressAndMomentum(const std::array<Field, 6>& tau_layout);
  void run(const FieldSet& s, const Physics& ph, Field& root, std::array<Field, 3>& dvdt, const RateOutput& out);

 private:
  std::vector<TauRing> rings_;  // one per thread
};

// dphi/dt = -v.grad phi; dBt/dt = -v.grad Bt + L.Bt + Bt.L^T, with the WENO5 upwind
// derivative, on `cells` (extended to the owned top wall face for the components staggered
// in y: owned_extent).  With solid_cutoff > 0 (the solid cut-off, solid_cutoff.hpp), the
// Euler update comes out with the cut-off applied (reset_solid_debris, line by line); the
// rates are left unwritten on the parts of a line that the cut-off would reset.
void transport_tendency(const FieldSet& s, Field& dphidt, std::array<Field, 6>& dBdt, const Box& cells,
                        double solid_cutoff = 0.0, const RateOutput& out = {});

// `cells` extended to q's owned top wall face when q is staggered in y (field.hpp).
Box owned_extent(const Field& q, const Box& cells);
// What owned_extent adds to `cells`: the slab of q's owned top wall face (empty if none).
Box owned_top_face(const Field& q, const Box& cells);

// The pieces of the Crank-Nicolson stress iteration (docs/numerics.md, "SMAC"), same stencils as above.
// tau from s's velocity and Bt* = base + dt (L.Bt + Bt.L^T) (L and Bt from s), on the owned
// points of every component (top wall faces included): add_stretching then compute_stress,
// fused along each line so that Bt* is never stored.  `root` must hold sqrt(phi) of s's phi
// on the centres these points read, as compute_stress over the full boxes leaves it.
void stretched_stress_owned(const FieldSet& s, const Physics& ph, double dt, const std::array<Field, 6>& base,
                            const Field& root, std::array<Field, 6>& tau);
// out = base + dt (L.Bt + Bt.L^T), L from s's velocity and Bt from s, on `cells` (extended
// to the owned top wall face like compute_transport).
void add_stretching(const FieldSet& s, double dt, const std::array<Field, 6>& base, std::array<Field, 6>& out,
                    const Box& cells);
// out = base + c div tau on the faces of `faces` (wall faces of v set to zero), div tau
// summed as the momentum equation sums it.  The Crank-Nicolson iteration calls it once
// with the explicit stress and -c (its explicit half, the same in every sweep) and then in
// every sweep with the iterate's stress and c on that base.
void add_stress_divergence(const FieldSet& s, const std::array<Field, 6>& tau, double c,
                           const std::array<Field, 3>& base, std::array<Field, 3>& out, const Box& faces);

}  // namespace efsi
