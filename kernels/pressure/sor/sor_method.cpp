// SMAC-SOR's registration (method_spec.hpp): N_S sweeps per step from --ns or from the
// calibrated count for --eps, Crank-Nicolson stress with the paper's N_C by default, the
// paper's 10 steps of 6.25e-5.
#include <cmath>
#include <string>

#include "config_error.hpp"
#include "method_spec.hpp"
#include "paper_constants.hpp"
#include "smac_sor.hpp"
#include "sor_work.hpp"

namespace efsi {
namespace {

// "1e-3", as the calibration's eps are written.
std::string format_eps(double v) {
  const int exponent = static_cast<int>(std::lround(std::log10(v)));
  return std::pow(10.0, exponent) == v ? "1e" + std::to_string(exponent) : format_value(v);
}

int calibrated_sweeps(double eps) {
  std::string known;
  for (const auto& c : paper::kCalibratedSorSweeps) {
    if (c.eps == eps) return c.sweeps;
    known += (known.empty() ? "" : ", ") + format_eps(c.eps);
  }
  throw ConfigError("no calibrated SOR sweep count for --eps " + format_value(eps) + " (calibrated: " + known +
                    "); give --ns, or find one with --calibrate");
}

// The paper's calibration of N_S: sweeps from x = 0 until the RMS residual is at most eps
// times its initial value.
class SorCounter final : public IterationCounter {
 public:
  SorCounter(const CartDecomposition& decomp, const Domain& domain)
      : x_(decomp, {"dp_sor", Stagger::cell, 1, WallParity::even}), sor_(decomp, domain, x_, CommMode::sync) {}
  std::vector<double> residuals(const Field& rhs, double factor, double eps, int max_iterations) override {
    x_.fill(0.0);
    std::vector<double> out;
    const double r0 = sor_.residual_rms(rhs, factor);
    if (!(r0 > 0.0)) return out;
    for (int n = 1; n <= max_iterations; ++n) {
      sor_.sweeps(rhs, 1, factor);
      out.push_back(sor_.residual_rms(rhs, factor) / r0);
      if (out.back() <= eps) break;
    }
    return out;
  }
  const Field& solution() const override { return x_; }

 private:
  Field x_;
  SorPoisson sor_;
};

constexpr int kCampaignSweepsPerExchange = 4;

class SorSpec final : public MethodSpec {
 public:
  std::string name() const override { return "sor"; }
  std::string summary() const override { return "SMAC with N_S four-colour SOR sweeps per step"; }
  std::vector<MethodOption> options() const override {
    return {{"--eps", "SOR: the residual ratio that picks the calibrated N_S (1e-3 or 1e-4; default 1e-3), or the "
                      "target of --calibrate", false},
            {"--ns", "SOR sweeps per step N_S (overrides --eps)", true},
            {"--sweeps-per-exchange", "SOR: K sweeps between two exchanges of ghosts 2K deep "
                                      "(temporal blocking, bitwise the same field; default 1: the paper's exchange "
                                      "after every colour pass)", true}};
  }
  int default_cn_sweeps() const override { return paper::kCnSweeps; }
  ScalingDefaults scaling_defaults() const override { return {paper::kSmacDt, paper::kSmacSteps}; }
  // The paper's pattern at each calibrated tolerance, then the same with temporal blocking
  // (kCampaignSweepsPerExchange sweeps between exchanges: ghosts 8 deep fit every block of
  // the paper's sweeps), an extra series at the same N_S.
  std::vector<CampaignVariant> campaign_variants() const override {
    std::vector<CampaignVariant> out;
    for (const auto& c : paper::kCalibratedSorSweeps) out.push_back({format_eps(c.eps), {"--eps", format_eps(c.eps)}});
    const std::string k = std::to_string(kCampaignSweepsPerExchange);
    for (const auto& c : paper::kCalibratedSorSweeps)
      out.push_back({format_eps(c.eps) + "-k" + k, {"--eps", format_eps(c.eps), "--sweeps-per-exchange", k}});
    return out;
  }

  void configure(const OptionValues& given, bool calibrating, MethodChoice& choice) const override {
    const auto eps = given.find("--eps"), ns = given.find("--ns"), spe = given.find("--sweeps-per-exchange");
    if (spe != given.end() && !(spe->second >= 1))
      throw ConfigError("--sweeps-per-exchange " + format_value(spe->second) + " must be at least 1");
    const int blocking = spe != given.end() ? static_cast<int>(spe->second) : 1;
    choice.values["sweeps_per_exchange"] = blocking;
    if (eps != given.end() && !(eps->second > 0 && eps->second < 1))
      throw ConfigError("--eps " + format_value(eps->second) + " must lie in (0, 1)");
    if (ns != given.end()) check_sor_sweeps(ns->second, "--ns");
    const double e = eps != given.end() ? eps->second : paper::kDefaultSorEps;
    choice.values["eps"] = e;
    if (calibrating) return;  // the calibration counts the sweeps; it needs none
    const int sweeps = ns != given.end() ? static_cast<int>(ns->second) : calibrated_sweeps(e);
    choice.values["ns"] = sweeps;
    choice.report["ns_per_step"] = std::to_string(sweeps);
    // The eps that chose N_S; none when --ns alone set it.
    if (ns == given.end() || eps != given.end()) choice.report["eps"] = format_value(e);
    choice.report["sweeps_per_exchange"] = std::to_string(blocking);
    choice.banner = "N_S = " + std::to_string(sweeps) + " SOR sweeps per step";
    if (blocking > 1) choice.banner += ", " + std::to_string(blocking) + " between exchanges";
  }

  void check_grid(const Int3& cells) const override { check_sor_grid(cells); }

  // dp cleared, N_S sweeps of four colours in 2 or 4 passes, each pass followed by an
  // exchange of x's faces, and one exchange before the first.  Blocked (K sweeps an
  // exchange): x and rhs copied in and x out, ceil(N_S / K) exchanges of ghosts 2K
  // deep (rhs with the first), and the one that leaves x's ghosts current.  The ghosts the
  // passes update besides the owned points are not counted.
  IncrementWork increment_work(const MethodChoice& choice, const Int3&, const Int3& dims) const override {
    const double ns = choice.value("ns");
    const int passes = sor_passes_per_sweep(dims);
    const int blocking = static_cast<int>(choice.value("sweeps_per_exchange"));
    if (blocking <= 1) return {kFill + ns * sor_sweep_cost(passes), passes * ns + 1};
    const double groups = std::ceil(ns / blocking), depth = 2.0 * blocking;
    return {kFill + ns * sor_sweep_cost(passes) + PerCell{48, 0}, (groups + 1) * depth + 1};
  }

  // x whole: colours 0 and 1 (2 and 3) share a pass and an exchange (sor_work.hpp).
  Int3 preferred_rank_grid() const override { return {1, 0, 0}; }

  std::optional<CalibratedCount> calibrated_count() const override {
    return CalibratedCount{"--ns", "sweeps", "SOR (omega " + format_value(paper::kSorOmega) + ") from dp = 0"};
  }
  std::unique_ptr<IterationCounter> iteration_counter(const CartDecomposition& decomp,
                                                      const Domain& domain) const override {
    return std::make_unique<SorCounter>(decomp, domain);
  }

  std::unique_ptr<PressureMethod> make(const MethodChoice& choice, const MethodBuild& build) const override {
    return std::make_unique<SmacSorPressure>(build.comm, static_cast<int>(choice.value("ns")), paper::kSorOmega,
                                             static_cast<int>(choice.value("sweeps_per_exchange")), build.halo);
  }
};

}  // namespace

const MethodSpec& sor_method() {
  static const SorSpec spec;
  return spec;
}

}  // namespace efsi
