#include "fsi_state.hpp"

#include <cmath>

#include "compute_model.hpp"

namespace efsi {

std::vector<FieldSpec> fsi_field_specs() {
  const int h = kTransportHalo;
  return {
      {"u", Stagger::face_x, 1, WallParity::odd},      {"v", Stagger::face_y, 1, WallParity::odd},
      {"w", Stagger::face_z, 1, WallParity::odd},      {"p", Stagger::cell, 1, WallParity::even},
      {"phi", Stagger::cell, h, WallParity::even},     {"Bt11", Stagger::cell, h, WallParity::even},
      {"Bt22", Stagger::cell, h, WallParity::even},    {"Bt33", Stagger::cell, h, WallParity::even},
      {"Bt12", Stagger::edge_xy, h, WallParity::even}, {"Bt13", Stagger::edge_xz, h, WallParity::even},
      {"Bt23", Stagger::edge_yz, h, WallParity::even},
  };
}

FsiState::FsiState(const CartDecomposition& decomp, const Domain& domain) : decomp_(decomp), domain_(domain) {
  const auto specs = fsi_field_specs();
  fields_.reserve(specs.size());
  for (const auto& s : specs) fields_.emplace_back(decomp, s);
}

FieldSet FieldSet::with_velocity(const std::array<Field, 3>& v) const {
  FieldSet out = *this;
  for (int a = 0; a < 3; ++a) out.vel_[a] = &v[a];
  return out;
}

FieldSet FieldSet::with_B(const std::array<Field, 6>& b) const {
  FieldSet out = *this;
  for (int n = 0; n < 6; ++n) out.B_[n] = &b[n];
  return out;
}

FieldSet FsiState::fields() const {
  return FieldSet(decomp_, domain_, {&vel(X), &vel(Y), &vel(Z)}, &p(), &phi(),
                  {&B(0), &B(1), &B(2), &B(3), &B(4), &B(5)});
}

std::vector<Field*> FsiState::all() {
  std::vector<Field*> out;
  for (Field& f : fields_) out.push_back(&f);
  return out;
}

std::vector<const Field*> FsiState::all() const {
  std::vector<const Field*> out;
  for (const Field& f : fields_) out.push_back(&f);
  return out;
}

void FsiState::set_unstrained_rest() {
  setup_stage([&] {
    for (int a = 0; a < 3; ++a) vel(a).fill(0.0);
    p().fill(0.0);
    for (int n = 3; n < 6; ++n) B(n).fill(0.0);
    const Field& ph = phi();
    const Int3 n = ph.n();
    for (int a = 0; a < 3; ++a) {
      Field& b = B(a, a);
  #pragma omp parallel for schedule(static)
      for (int k = 0; k < n[Z]; ++k)
        for (int j = 0; j < n[Y]; ++j)
          for (int i = 0; i < n[X]; ++i) b(i, j, k) = std::sqrt(std::max(ph(i, j, k), 0.0));
    }
  });
}

}  // namespace efsi
