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

// The V-cycles per step that reach each tolerance on the paper's weak-scaling block, by the
// calibration the paper made for SOR's N_S (channel --calibrate --method mg; the figures in
// docs/numerics.md, "Multigrid calibration").  The campaign runs these fixed counts, so
// that weak scaling keeps the work per rank fixed.
struct CalibratedCycles {
  const char* eps;
  int cycles;
};
constexpr CalibratedCycles kCalibratedCycles[] = {{"1e-3", 5}, {"1e-4", 7}};

// hypre's memory per cell of the block, in 8-byte words: the 7-point matrix, b and x, the
// PFMG hierarchy (coarse matrices and work vectors) and its communication packages, and the
// method's own transfer buffer.  Measured as the resident size of `channel --particles 0
// --steps 1` with --method mg less that with --method sor on one rank: 28.9 words per cell
// at 64^3, 27.7 at 96^3 (dev-2core); the model takes 27, below both.
constexpr double kHypreWordsPerCell = 27.0;

// V-cycles from x = 0 until hypre's relative residual (the l2 norm of the residual over that
// of the right-hand side, as the SOR calibration's RMS ratio) is at most eps: the k-th
// solve runs exactly k cycles, since hypre reports the residual only at the end of a solve.
class MgCounter final : public IterationCounter {
 public:
  MgCounter(const CartDecomposition& decomp, const Domain& domain)
      : x_(decomp, {"dp_mg", Stagger::cell, 1, WallParity::even}), mg_(decomp, domain) {}
  std::vector<double> residuals(const Field& rhs, double factor, double eps, int max_iterations) override {
    std::vector<double> out;
    for (int n = 1; n <= max_iterations; ++n) {
      // A tolerance no solve reaches: hypre computes the residual after every cycle only
      // when it has one to test.
      out.push_back(mg_.solve(rhs, x_, factor, MgStop{1e-300, n}).residual);
      if (out.back() <= eps) break;
    }
    return out;
  }
  const Field& solution() const override { return x_; }

 private:
  Field x_;
  MgPoisson mg_;
};

// "5 for 1e-3, 7 for 1e-4"
std::string calibrated() {
  std::string out;
  for (const auto& c : kCalibratedCycles)
    out += (out.empty() ? "" : ", ") + std::to_string(c.cycles) + " for " + c.eps;
  return out;
}

class MgSpec final : public MethodSpec {
 public:
  std::string name() const override { return "mg"; }
  std::string summary() const override {
    return "SMAC with hypre's PFMG multigrid solve, to --eps or for --mg-iters V-cycles";
  }
  std::vector<MethodOption> options() const override {
    return {{"--eps", "multigrid: relative residual at which the solve stops (default 1e-3); with --mg-iters, "
                      "the tolerance that count was calibrated for, recorded in the CSV", false},
            {"--mg-iters", "multigrid V-cycles per step, a fixed count (the calibrated ones: " + calibrated() +
                               ")", true}};
  }
  bool supports(CommMode mode) const override { return mode == CommMode::sync; }
  int default_cn_sweeps() const override { return paper::kCnSweeps; }
  ScalingDefaults scaling_defaults() const override { return {paper::kSmacDt, paper::kSmacSteps}; }
  std::vector<CampaignVariant> campaign_variants() const override {
    std::vector<CampaignVariant> out;
    for (const auto& c : kCalibratedCycles)
      out.push_back({c.eps, {"--eps", c.eps, "--mg-iters", std::to_string(c.cycles)}});
    return out;
  }

  void configure(const OptionValues& given, bool, MethodChoice& choice) const override {
    const auto eps = given.find("--eps"), iters = given.find("--mg-iters");
    if (eps != given.end() && !(eps->second > 0 && eps->second < 1))
      throw ConfigError("--eps " + format_value(eps->second) + " must lie in (0, 1)");
    if (iters != given.end() && !(iters->second >= 1 && iters->second <= kMaxCycles))
      throw ConfigError("--mg-iters " + format_value(iters->second) + " must lie between 1 and " +
                        std::to_string(kMaxCycles));
    if (iters != given.end()) {
      const int n = static_cast<int>(iters->second);
      choice.values["mg_iters"] = n;
      choice.values["eps"] = 0.0;
      choice.report["ns_per_step"] = std::to_string(n);
      if (eps != given.end()) choice.report["eps"] = format_value(eps->second);
      choice.banner = std::to_string(n) + " multigrid V-cycles per step" +
                      (eps != given.end() ? " (calibrated for " + format_value(eps->second) + ")" : "");
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

  std::optional<CalibratedCount> calibrated_count() const override {
    return CalibratedCount{"--mg-iters", "V-cycles", "PFMG V(2,1) from dp = 0"};
  }
  std::unique_ptr<IterationCounter> iteration_counter(const CartDecomposition& decomp,
                                                      const Domain& domain) const override {
    return std::make_unique<MgCounter>(decomp, domain);
  }

  std::unique_ptr<PressureMethod> make(const MethodChoice& choice, const MethodBuild&) const override {
    return std::make_unique<SmacMgPressure>(
        MgStop{choice.value("eps"), static_cast<int>(choice.value("mg_iters"))});
  }

  // hypre's own counts are not modelled: its increment counts as the right-hand side and
  // the result copied in and out (8 B in, 8 B out, 8 B each way through its vectors).
  IncrementWork increment_work(const MethodChoice&, const Int3&, const Int3&) const override { return {{32, 2}, 1}; }
};

}  // namespace

const MethodSpec& mg_method() {
  static const MgSpec spec;
  return spec;
}

}  // namespace efsi
