#pragma once
// a b + c rounded once, where the target has the instruction (FMA3: Haswell, Zen and later;
// every -march=native build on this project's hosts, and the counted gate's x86-64-v3).
// std::fma is one instruction in a loop's vector body and in its scalar remainder alike,
// so a point rounds the same wherever its loop starts.  The build keeps -ffp-contract=off
// for every other product and sum, which the compiler might fuse in one and not the other.
// A target without FMA gets the two roundings of a * b + c.
#include <cmath>

namespace efsi {

[[gnu::always_inline]] inline double mul_add(double a, double b, double c) {
#if defined(__FMA__)
  return std::fma(a, b, c);
#else
  return a * b + c;
#endif
}

}  // namespace efsi
