// SMAC-MG's registration (method_spec.hpp): hypre's PFMG to --eps (default 1e-3, the
// paper's SOR tolerance) or for --mg-iters V-cycles, Crank-Nicolson stress with the paper's
// N_C by default as for SOR, the paper's 10 steps of 6.25e-5.  hypre does its own exchanges,
// so there is no asynchronous halo mode.
#include <cmath>
#include <string>

#include "config_error.hpp"
#include "method_spec.hpp"
#include "mg_poisson.hpp"
#include "paper_constants.hpp"
#include "smac_mg.hpp"

namespace efsi {
namespace {

constexpr int kMaxCycles = 1000;  // a tolerance no V-cycle count reaches stops here

// hypre's memory per cell of the block, in 8-byte words: the 7-point matrix, b and x, the
// PFMG hierarchy (coarse matrices and work vectors) and its communication packages, and the
// method's own transfer buffer.  Measured as the resident size of `channel --particles 0
// --steps 1` with --method mg less that with --method sor on one rank: 28.9 words per cell
// at 64^3, 27.7 at 96^3 (dev-2core); the model takes 27, below both.
constexpr double kHypreWordsPerCell = 27.0;

class MgSpec final : public MethodSpec {
 public:
  std::string name() const override { return "mg"; }
  std::string summary() const override {
    return "SMAC with hypre's PFMG multigrid solve, to --eps or for --mg-iters V-cycles";
  }
  std::vector<MethodOption> options() const override {
    return {{"--eps", "multigrid: relative residual at which the solve stops (default 1e-3)", false},
            {"--mg-iters", "multigrid V-cycles per step, a fixed count (overrides --eps)", true}};
  }
  bool supports(CommMode mode) const override { return mode == CommMode::sync; }
  int default_cn_sweeps() const override { return paper::kCnSweeps; }
  ScalingDefaults scaling_defaults() const override { return {paper::kSmacDt, paper::kSmacSteps}; }
  std::vector<CampaignVariant> campaign_variants() const override {
    return {{"1e-3", {"--eps", "1e-3"}}, {"1e-4", {"--eps", "1e-4"}}};
  }

  void configure(const OptionValues& given, bool, MethodChoice& choice) const override {
    const auto eps = given.find("--eps"), iters = given.find("--mg-iters");
    if (eps != given.end() && !(eps->second > 0 && eps->second < 1))
      throw ConfigError("--eps " + format_value(eps->second) + " must lie in (0, 1)");
    if (iters != given.end() && !(iters->second >= 1 && iters->second <= kMaxCycles))
      throw ConfigError("--mg-iters " + format_value(iters->second) + " must lie between 1 and " +
                        std::to_string(kMaxCycles));
    if (iters != given.end()) {
      choice.values["mg_iters"] = iters->second;
      choice.values["eps"] = 0.0;
      choice.banner = std::to_string(static_cast<int>(iters->second)) + " multigrid V-cycles per step";
    } else {
      const double e = eps != given.end() ? eps->second : paper::kDefaultSorEps;
      choice.values["mg_iters"] = kMaxCycles;
      choice.values["eps"] = e;
      choice.report["eps"] = format_value(e);
      choice.banner = "multigrid to relative residual " + format_value(e);
    }
  }

  void check_grid(const Int3& cells) const override { check_mg_grid(cells); }
  std::string extra_bytes_hold() const override { return "hypre's matrix, vectors and hierarchy"; }
  double extra_bytes(const Int3& local, const Int3&) const override {
    return kHypreWordsPerCell * double(product(local)) * 8.0;
  }

  std::unique_ptr<PressureMethod> make(const MethodChoice& choice, const MethodBuild&) const override {
    return std::make_unique<SmacMgPressure>(
        MgStop{choice.value("eps"), static_cast<int>(choice.value("mg_iters"))});
  }

  // hypre's own counts are not modelled: its increment counts as the right-hand side and
  // the result copied in and out (8 B in, 8 B out, 8 B each way through its vectors).
  IncrementWork increment_work(const MethodChoice&, const Int3&) const override { return {{32, 2}, 1}; }
};

}  // namespace

const MethodSpec& mg_method() {
  static const MgSpec spec;
  return spec;
}

}  // namespace efsi
