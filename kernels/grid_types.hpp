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

}  // namespace efsi
