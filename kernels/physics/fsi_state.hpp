#pragma once
// The solver's state on the local block: velocity, pressure, solid fraction and the
// modified left Cauchy-Green tensor Bt = sqrt(phi) B, laid out as docs/numerics.md, "Staggered grid".
#include <array>
#include <vector>

#include "decomposition.hpp"
#include "domain.hpp"
#include "field.hpp"
#include "stencils.hpp"

namespace efsi {

struct Physics {
  double rho = 1.0;    // density of fluid and solid
  double mu = 1.0;     // viscosity of fluid and solid
  double G = 50.0;     // shear modulus of the neo-Hookean solid
  double force = 1.0;  // driving pressure gradient -dP/dx / Lx, along x
  double solid_cutoff = 0.0;  // phi below which Bt is reset to unstrained (solid_cutoff.hpp); 0: none
};

// Widest stencil: WENO5 reads three neighbours each side.
inline constexpr int kTransportHalo = 3;

// Index of Bt component (a, b) in FsiState::B: 11, 22, 33, 12, 13, 23.
constexpr int tensor_index(int a, int b) {
  if (a == b) return a;
  const int s = a + b;  // 1: xy, 2: xz, 3: yz
  return 2 + s;
}

// The eleven exchanged fields: u, v, w, p (halo 1), phi and six Bt components (halo 3).
std::vector<FieldSpec> fsi_field_specs();

// The fields an equation reads, by reference: the state's, or an iterate's in their place
// (Crank-Nicolson evaluates the stress on its iterate (v*, Bt*) this way, with no copy or
// swap).  Accessors as FsiState's.
class FieldSet {
 public:
  FieldSet(const CartDecomposition& decomp, const Domain& domain, std::array<const Field*, 3> vel, const Field* p,
           const Field* phi, std::array<const Field*, 6> B)
      : decomp_(&decomp), domain_(&domain), vel_(vel), p_(p), phi_(phi), B_(B) {}

  const Field& vel(int a) const { return *vel_[a]; }
  const Field& p() const { return *p_; }
  const Field& phi() const { return *phi_; }
  const Field& B(int a, int b) const { return *B_[tensor_index(a, b)]; }
  const Field& B(int n) const { return *B_[n]; }
  const Domain& domain() const { return *domain_; }
  const CartDecomposition& decomp() const { return *decomp_; }

  // The same set with another velocity or another Bt.
  FieldSet with_velocity(const std::array<Field, 3>& v) const;
  FieldSet with_B(const std::array<Field, 6>& b) const;

 private:
  const CartDecomposition* decomp_;
  const Domain* domain_;
  std::array<const Field*, 3> vel_;
  const Field* p_;
  const Field* phi_;
  std::array<const Field*, 6> B_;
};

class FsiState {
 public:
  FsiState(const CartDecomposition& decomp, const Domain& domain);

  Field& vel(int a) { return fields_[a]; }
  const Field& vel(int a) const { return fields_[a]; }
  Field& p() { return fields_[3]; }
  const Field& p() const { return fields_[3]; }
  Field& phi() { return fields_[4]; }
  const Field& phi() const { return fields_[4]; }
  Field& B(int a, int b) { return fields_[5 + tensor_index(a, b)]; }
  const Field& B(int a, int b) const { return fields_[5 + tensor_index(a, b)]; }
  Field& B(int n) { return fields_[5 + n]; }
  const Field& B(int n) const { return fields_[5 + n]; }

  std::vector<Field*> all();  // in fsi_field_specs() order
  std::vector<const Field*> all() const;
  FieldSet fields() const;
  const Domain& domain() const { return domain_; }
  const CartDecomposition& decomp() const { return decomp_; }

  // Bt = sqrt(phi0) I, v = 0, p = 0 (docs/numerics.md, "Governing equations"); owned points only.
  void set_unstrained_rest();

 private:
  const CartDecomposition& decomp_;
  Domain domain_;
  std::vector<Field> fields_;
};

}  // namespace efsi
