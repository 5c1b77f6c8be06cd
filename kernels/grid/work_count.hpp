#pragma once
// Bytes and flops per owned cell of a kernel, counted from its code: the benchmarks
// (harness/microbench) turn them into GB/s, GFLOP/s and fractions of the machine's roofs,
// and the simulation build charges them as a stage's time (compute_model.hpp).  The
// physics kernels are counted in kernels/physics/kernel_costs.hpp; each pressure method
// counts its own increment (method_spec.hpp).
//
// Conventions (the same for every kernel):
//   bytes  what the kernel must move between memory and the core: every array it reads
//          read once, every array it writes written once, 8 bytes per double per owned cell
//          (ghost points not counted; no write-allocate read, as STREAM counts its triad);
//          a kernel made of separate passes (SOR colours, FFT stages) moves its data once
//          per pass.
//   flops  + - * / and sqrt, 1 each, as written in the source for one output point, with no
//          sharing between points or between terms (the compiler may share some); max, abs
//          and the upwind selects are not counted; an average of m points costs m - 1 adds
//          and one multiply (none when m = 1).

namespace efsi {

struct PerCell {
  double bytes = 0, flops = 0;
};
constexpr PerCell operator+(PerCell a, PerCell b) { return {a.bytes + b.bytes, a.flops + b.flops}; }
constexpr PerCell operator*(double s, PerCell a) { return {s * a.bytes, s * a.flops}; }

}  // namespace efsi
