// The exact SMAC reference's registration (method_spec.hpp): explicit stress unless --nc,
// the paper's 10 steps of 6.25e-5, and the FFT solver's pencils in the memory model.
#include "fft_work.hpp"
#include "method_spec.hpp"
#include "paper_constants.hpp"
#include "smac_fft.hpp"

namespace efsi {
namespace {

// FftPoisson per cell of the block, in 8-byte words (fft_poisson.cpp): the block and the
// r2c output (1 + 1: half the points as complex numbers).  Each transpose that crosses
// ranks or reorders adds its pencil and its send and receive buffers with their int64 index
// lists; one that is a copy shares its buffers and adds nothing: the real x transpose (x
// split) 1 + 2 + 2, the complex ones, half the points as complex numbers, 1 + 2 x 1 + 2 x 1/2
// each (z split; x or y split).
double fft_words_per_cell(const Int3& dims) {
  double words = 2.0;
  if (dims[X] > 1) words += 5.0;
  if (dims[Z] > 1) words += 4.0;
  if (dims[X] * dims[Y] > 1) words += 4.0;
  return words;
}

class FftSpec final : public MethodSpec {
 public:
  std::string name() const override { return "fft"; }
  std::string summary() const override { return "SMAC with the exact FFT (x, z) + tridiagonal (y) solve: the reference"; }
  ScalingDefaults scaling_defaults() const override { return {paper::kSmacDt, paper::kSmacSteps}; }
  void configure(const OptionValues&, bool, MethodChoice&) const override {}
  std::unique_ptr<PressureMethod> make(const MethodChoice&, const MethodBuild& build) const override {
    return std::make_unique<SmacFftPressure>(build.timed_planning ? FftPoisson::Planning::measure
                                                                  : FftPoisson::Planning::estimate);
  }
  std::string extra_bytes_hold() const override { return "FFT pencils and transposes"; }
  double extra_bytes(const Int3& local, const Int3& dims) const override {
    return fft_words_per_cell(dims) * double(product(local)) * 8.0;
  }
  // x whole: the r2c transform along x needs no transpose, and the solve two transposes
  // across ranks instead of four (1.28x on a 128^3 channel on 2 ranks).
  Int3 preferred_rank_grid() const override { return {1, 0, 0}; }
  // One solve, then the exchange of dp's faces for the projection.
  IncrementWork increment_work(const MethodChoice&, const Int3& global, const Int3&) const override {
    return {fft_solve_cost(global[X], global[Z]), 1};
  }
};

}  // namespace

const MethodSpec& fft_method() {
  static const FftSpec spec;
  return spec;
}

}  // namespace efsi
