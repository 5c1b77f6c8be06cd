#include "field.hpp"

#include <algorithm>
#include <cstdlib>
#include <new>

#include "config_error.hpp"
#include "simulation.hpp"

namespace efsi {
namespace {

std::ptrdiff_t round_up(std::ptrdiff_t v, std::ptrdiff_t m) { return (v + m - 1) / m * m; }

FieldRecorder* active_recorder = nullptr;

// Leading pad so that i = 0 is aligned; rows a multiple of the alignment.
std::ptrdiff_t leading_pad(int h) { return round_up(h, Field::kAlignDoubles); }
std::ptrdiff_t row_stride(const Int3& n, int h) { return round_up(leading_pad(h) + n[X] + h, Field::kAlignDoubles); }

}  // namespace

const char* to_string(Stagger s) {
  switch (s) {
    case Stagger::cell: return "cell";
    case Stagger::face_x: return "face_x";
    case Stagger::face_y: return "face_y";
    case Stagger::face_z: return "face_z";
    case Stagger::edge_xy: return "edge_xy";
    case Stagger::edge_xz: return "edge_xz";
    case Stagger::edge_yz: return "edge_yz";
  }
  return "?";
}



Field::Field(const CartDecomposition& decomp, FieldSpec spec)
    : spec_(std::move(spec)), n_(decomp.local()), owned_end_(decomp.local()), offset_(decomp.offset()) {
  const int h = spec_.halo;
  if (h < 1) throw ConfigError("field " + spec_.name + ": halo width " + std::to_string(h) + " must be at least 1");
  for (int a = 0; a < 3; ++a)
    if (n_[a] < h)
      throw ConfigError("field " + spec_.name + ": local block " + to_string(n_) + " is thinner than its halo width " +
                        std::to_string(h));
  if (is_staggered(spec_.stagger, Y) && decomp.wall_above()) owned_end_[Y] = n_[Y] + 1;

  sy_ = row_stride(n_, h);
  sz_ = sy_ * (n_[Y] + 2 * h);
  size_ = allocation_doubles(n_, h);
  origin_ = leading_pad(h) + sy_ * h + sz_ * h;
  if (active_recorder) active_recorder->specs_.push_back(spec_);

  data_ = allocate_storage(size_, false);
  // First touch by the threads that will work on the data; folded simulated storage
  // (storage.hpp) is never read.
  if constexpr (!kSimulated) fill(0.0);
}

std::size_t Field::allocation_doubles(const Int3& local, int halo) {
  return static_cast<std::size_t>(row_stride(local, halo) * (local[Y] + 2 * halo) * (local[Z] + 2 * halo));
}

FieldRecorder::FieldRecorder() {
  if (active_recorder) throw ConfigError("FieldRecorder: another recorder is active");
  active_recorder = this;
}

FieldRecorder::~FieldRecorder() { active_recorder = nullptr; }

void Field::fill(double value) {
  double* d = data_.get();
  const std::ptrdiff_t planes = n_[Z] + 2 * spec_.halo;
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t k = 0; k < planes; ++k)
    for (std::ptrdiff_t m = 0; m < sz_; ++m) d[k * sz_ + m] = value;
}

void Field::copy_from(const Field& other) {
  if (other.size_ != size_ || other.sz_ != sz_ || other.sy_ != sy_ || other.n_ != n_ ||
      other.spec_.stagger != spec_.stagger || other.spec_.halo != spec_.halo)
    throw ConfigError("Field::copy_from: '" + other.name() + "' and '" + name() + "' have different layouts");
  double* d = data_.get();
  const double* o = other.data_.get();
  const std::ptrdiff_t planes = n_[Z] + 2 * spec_.halo;
#pragma omp parallel for schedule(static)
  for (std::ptrdiff_t k = 0; k < planes; ++k)
    for (std::ptrdiff_t m = 0; m < sz_; ++m) d[k * sz_ + m] = o[k * sz_ + m];
}

void Field::copy_owned_from(const Field& other) {
  if (other.n_ != n_ || other.spec_.stagger != spec_.stagger)
    throw ConfigError("Field::copy_owned_from: '" + other.name() + "' and '" + name() + "' hold different points");
  const Int3& m = n_;
#pragma omp parallel for collapse(2) schedule(static)
  for (int k = 0; k < m[Z]; ++k)
    for (int j = 0; j < m[Y]; ++j) {
      const double* from = other.data() + other.index(0, j, k);
      std::copy(from, from + m[X], data() + index(0, j, k));
    }
}

}  // namespace efsi
