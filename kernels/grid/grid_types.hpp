#pragma once
#include <array>
#include <cstdint>
#include <string>

namespace efsi {

using Int3 = std::array<int, 3>;

enum Axis : int { X = 0, Y = 1, Z = 2 };

inline std::int64_t product(const Int3& a) {
  return std::int64_t{a[0]} * a[1] * a[2];
}

// "64x32x16"
inline std::string to_string(const Int3& a) {
  return std::to_string(a[0]) + "x" + std::to_string(a[1]) + "x" + std::to_string(a[2]);
}

// Half-open index box [lo, hi) on the local block.
struct Box {
  Int3 lo{}, hi{};
  bool empty() const { return hi[0] <= lo[0] || hi[1] <= lo[1] || hi[2] <= lo[2]; }
  std::int64_t volume() const {
    return empty() ? 0 : std::int64_t{hi[0] - lo[0]} * (hi[1] - lo[1]) * (hi[2] - lo[2]);
  }
};

// [lo - grow, hi + grow) on every axis (grow may be negative).
inline Box grown(const Box& b, int grow) {
  return {{b.lo[0] - grow, b.lo[1] - grow, b.lo[2] - grow}, {b.hi[0] + grow, b.hi[1] + grow, b.hi[2] + grow}};
}

// Disjoint boxes covering outer minus inner (inner inside outer, or empty): the parts of a
// kernel's range that need ghosts, done after the halo exchange has finished.
template <class F>
void for_each_shell_box(const Box& outer, const Box& inner, F&& f) {
  if (inner.empty()) {
    if (!outer.empty()) f(outer);
    return;
  }
  const Box zlo{outer.lo, {outer.hi[0], outer.hi[1], inner.lo[2]}};
  const Box zhi{{outer.lo[0], outer.lo[1], inner.hi[2]}, outer.hi};
  const Box ylo{{outer.lo[0], outer.lo[1], inner.lo[2]}, {outer.hi[0], inner.lo[1], inner.hi[2]}};
  const Box yhi{{outer.lo[0], inner.hi[1], inner.lo[2]}, {outer.hi[0], outer.hi[1], inner.hi[2]}};
  const Box xlo{{outer.lo[0], inner.lo[1], inner.lo[2]}, {inner.lo[0], inner.hi[1], inner.hi[2]}};
  const Box xhi{{inner.hi[0], inner.lo[1], inner.lo[2]}, {outer.hi[0], inner.hi[1], inner.hi[2]}};
  for (const Box& b : {zlo, zhi, ylo, yhi, xlo, xhi})
    if (!b.empty()) f(b);
}

}  // namespace efsi
