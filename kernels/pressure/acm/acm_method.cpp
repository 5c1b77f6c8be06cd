// ACM's registration (method_spec.hpp): no options of its own, explicit stress, the
// paper's 50 steps of 1.25e-5.
#include "acm.hpp"
#include "acm_work.hpp"
#include "method_spec.hpp"
#include "paper_constants.hpp"

namespace efsi {
namespace {

class AcmSpec final : public MethodSpec {
 public:
  std::string name() const override { return "acm"; }
  std::string summary() const override { return "explicit artificial compressibility, adaptive beta and gamma"; }
  ScalingDefaults scaling_defaults() const override { return {paper::kAcmDt, paper::kAcmSteps}; }
  void configure(const OptionValues&, bool, MethodChoice&) const override {}
  std::unique_ptr<PressureMethod> make(const MethodChoice&, const MethodBuild&) const override {
    return std::make_unique<AcmPressure>();
  }
  IncrementWork increment_work(const MethodChoice&, const Int3&, const Int3&) const override {
    return {kAcmMoments + kAcmUpdate, 0};
  }
};

}  // namespace

const MethodSpec& acm_method() {
  static const AcmSpec spec;
  return spec;
}

}  // namespace efsi
