#pragma once
// Staggered fields on the local block (docs/numerics.md, "Staggered grid").
//
// Index convention: the owned points of every staggering are 0..n-1 along each axis,
// where point i of a staggered axis is the face (or edge) at the low side of cell i.
// One exception: a field staggered in y on the rank next to the top wall also owns
// j = ny, the wall face itself (the bottom wall face j = 0 is owned by construction),
// so that both walls carry a value the kernels can write and the halo can mirror.
//
// Memory: x fastest, then y, then z; halo h on every side; each x-row padded so that
// owned point i = 0 starts a 64-byte line, for aligned vector loads.
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "decomposition.hpp"
#include "grid_types.hpp"
#include "storage.hpp"

namespace efsi {

enum class Stagger { cell, face_x, face_y, face_z, edge_xy, edge_xz, edge_yz };

// Which axes a staggering sits on faces of (rather than cell centres).
constexpr bool is_staggered(Stagger s, int axis) {
  switch (s) {
    case Stagger::cell: return false;
    case Stagger::face_x: return axis == X;
    case Stagger::face_y: return axis == Y;
    case Stagger::face_z: return axis == Z;
    case Stagger::edge_xy: return axis == X || axis == Y;
    case Stagger::edge_xz: return axis == X || axis == Z;
    case Stagger::edge_yz: return axis == Y || axis == Z;
  }
  return false;
}

const char* to_string(Stagger s);

// Symmetry across the walls y = 0 and y = Ly that the halo exchange applies.
// odd: the field vanishes on the wall (no-slip velocities); even: zero normal gradient.
enum class WallParity { even, odd };

struct FieldSpec {
  std::string name;
  Stagger stagger = Stagger::cell;
  int halo = 1;
  WallParity parity = WallParity::even;
};

class Field {
 public:
  static constexpr int kAlignDoubles = 8;  // 64 bytes

  Field(const CartDecomposition& decomp, FieldSpec spec);
  // Doubles a field with this local block and halo allocates, padding included.
  static std::size_t allocation_doubles(const Int3& local, int halo);
  Field(Field&&) noexcept = default;
  Field& operator=(Field&&) noexcept = default;

  const FieldSpec& spec() const { return spec_; }
  const std::string& name() const { return spec_.name; }
  Stagger stagger() const { return spec_.stagger; }
  int halo() const { return spec_.halo; }
  const Int3& n() const { return n_; }
  // One past the last owned index along `axis` (n, or n + 1 for the top wall face).
  int owned_end(int axis) const { return owned_end_[axis]; }
  const Int3& offset() const { return offset_; }  // global index of local point 0

  std::ptrdiff_t stride_y() const { return sy_; }
  std::ptrdiff_t stride_z() const { return sz_; }
  std::ptrdiff_t index(int i, int j, int k) const { return origin_ + i + sy_ * j + sz_ * k; }
  double& operator()(int i, int j, int k) { return data_[index(i, j, k)]; }
  double operator()(int i, int j, int k) const { return data_[index(i, j, k)]; }
  double* data() { return data_.get(); }
  const double* data() const { return data_.get(); }
  std::size_t allocated() const { return size_; }  // doubles, padding included

  // Position along `axis` in cell widths: offset + i for staggered axes, + 1/2 for centred.
  double coord(int axis, int i) const {
    return offset_[axis] + i + (is_staggered(spec_.stagger, axis) ? 0.0 : 0.5);
  }

  // Sets every point, ghosts included.
  void fill(double value);
  // Every point, ghosts included, from a field of the same layout (throws otherwise).
  void copy_from(const Field& other);
  // The owned points alone from a field of the same extent and stagger, whatever its halo
  // (throws otherwise); the ghosts stay as they are.
  void copy_owned_from(const Field& other);

 private:
  FieldSpec spec_;
  Int3 n_{}, owned_end_{}, offset_{};
  std::ptrdiff_t sy_ = 0, sz_ = 0, origin_ = 0;
  std::size_t size_ = 0;
  Storage data_;
};

// Records the spec of every Field constructed while it lives, so that a memory estimate
// can learn which fields a solver makes from a small build instead of a full-size one.
// One recorder at a time, on the thread that builds.
class FieldRecorder {
 public:
  FieldRecorder();
  ~FieldRecorder();
  FieldRecorder(const FieldRecorder&) = delete;
  FieldRecorder& operator=(const FieldRecorder&) = delete;
  const std::vector<FieldSpec>& specs() const { return specs_; }

 private:
  friend class Field;
  std::vector<FieldSpec> specs_;
};

}  // namespace efsi
