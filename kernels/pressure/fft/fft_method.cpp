// The exact SMAC reference's registration (method_spec.hpp): explicit stress unless --nc,
// the paper's 10 steps of 6.25e-5, and the FFT solver's pencils in the memory model.
#include "fft_work.hpp"
#include "method_spec.hpp"
#include "paper_constants.hpp"
#include "smac_fft.hpp"

namespace efsi {
namespace {

// FftPoisson per cell of the block, in 8-byte words (fft_poisson.cpp): the block, x-pencil,
// r2c output, z-pencil and y-pencil buffers (5); the real x transpose's send and receive
// buffers and int64 index lists (4); the two complex transposes, half the points as
// complex numbers: buffers 2 x 1 and index lists 2 x 1/2 each (3 + 3).
constexpr double kFftWordsPerCell = 15.0;

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
  double extra_bytes(const Int3& local) const override { return kFftWordsPerCell * double(product(local)) * 8.0; }
  // One solve, then the exchange of dp's faces for the projection.
  IncrementWork increment_work(const MethodChoice&, const Int3& global) const override {
    return {fft_solve_cost(global[X], global[Z]), 1};
  }
};

}  // namespace

const MethodSpec& fft_method() {
  static const FftSpec spec;
  return spec;
}

}  // namespace efsi
