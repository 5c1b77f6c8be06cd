#pragma once
// How a pressure method presents itself to the rest of the suite (docs/architecture.md,
// "Adding a pressure method"): its name, its options with their checks and the paper's
// defaults, what it reports in the CSV and the banner, the memory it needs beyond its
// Fields, and how to build it.  Its timer regions it defines itself (region_timers.hpp,
// define_region).  Each method folder under kernels/pressure/ implements one MethodSpec;
// the registry lists them all.
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "comm_mode.hpp"
#include "decomposition.hpp"
#include "domain.hpp"
#include "field.hpp"
#include "grid_types.hpp"
#include "halo_exchange.hpp"
#include "pressure_method.hpp"
#include "work_count.hpp"

namespace efsi {

struct MethodOption {
  std::string flag;  // "--ns"
  std::string help;
  bool integer = false;  // a count: a fractional value is refused
};

// The values given on the command line for the methods' options, by flag ("--ns" -> 40);
// a flag that was not given is absent.
using OptionValues = std::map<std::string, double>;

// A scaling run's time step and measured steps when the user gives none.
struct ScalingDefaults {
  double dt;
  long steps;
};

// One setting a scaling campaign runs the method at besides its halo modes: SOR at each
// calibrated tolerance.  The campaign names the configuration METHOD-COMM-LABEL.
struct CampaignVariant {
  std::string label;              // "1e-3"
  std::vector<std::string> args;  // {"--eps", "1e-3"}
};

// The counted work of one pressure increment (work_count.hpp), for the benchmarks' figures
// of a whole step: the method's own kernels per owned cell, and how many times it
// exchanges the faces of one cell-centred field.
struct IncrementWork {
  PerCell kernels;
  double cell_face_exchanges = 0;
};

class MethodSpec;

// A method whose work per step is an iteration count calibrated on one rank (SOR's N_S
// sweeps, MG's V-cycles; kernels/cases/calibration.hpp) counts its iterations through this.
class IterationCounter {
 public:
  virtual ~IterationCounter() = default;
  // From x = 0 on Lap x = factor rhs: the relative RMS residual ||factor rhs - Lap x|| /
  // ||factor rhs|| after iterations 1, 2, ..., until one is at most `eps` or after
  // `max_iterations`.  Leaves x after the last.  Collective.
  virtual std::vector<double> residuals(const Field& rhs, double factor, double eps, int max_iterations) = 0;
  virtual const Field& solution() const = 0;
};

// What a method's calibration counts, for its report.
struct CalibratedCount {
  std::string flag;       // the option that sets the count: "--ns"
  std::string unit;       // "sweeps"
  std::string procedure;  // "SOR (omega 1.6) from dp = 0"
};

// A method configured for a run: everything the run needs from it besides the solver's
// own configuration.
struct MethodChoice {
  const MethodSpec* spec = nullptr;
  std::map<std::string, double> values;       // resolved settings by name ("ns" -> 213)
  int cn_sweeps = 0;                          // N_C: --nc, else the method's default
  std::map<std::string, std::string> report;  // the CSV cells it fills ("eps", "ns_per_step")
  std::string banner;                         // one line on what it chose ("" for nothing)

  std::string name() const;
  double value(const std::string& key) const;  // a resolved setting; std::logic_error if absent
};

// What building a method needs besides its choice.
struct MethodBuild {
  CommMode comm = CommMode::sync;
  HaloPattern halo = HaloPattern::direct;  // how a method's own full exchanges reach edges and corners
  // Whether the method may pick among equivalent algorithms by timing them (FFTW_MEASURE).
  // The bitwise tests and the counted CI gate need the same choice every run.
  bool timed_planning = true;
};

class MethodSpec {
 public:
  virtual ~MethodSpec() = default;
  virtual std::string name() const = 0;
  virtual std::string summary() const = 0;  // one line for --help
  virtual std::vector<MethodOption> options() const { return {}; }
  virtual bool supports(CommMode) const { return true; }
  virtual int default_cn_sweeps() const { return 0; }
  // Throws ConfigError for a global grid the method cannot work on (before allocating).
  virtual void check_grid(const Int3& /*cells*/) const {}
  virtual ScalingDefaults scaling_defaults() const = 0;
  // The rank grid pattern the method runs fastest on (0: free), used where the user forces
  // none and it fits the grid (rank_grid in kernels/cases/channel_case.hpp).
  virtual Int3 preferred_rank_grid() const { return {0, 0, 0}; }
  // The settings a campaign sweeps; none: the method runs once per halo mode.
  virtual std::vector<CampaignVariant> campaign_variants() const { return {}; }
  // Resolves and checks the method's own settings from `given` (only its own flags), and
  // fills choice.values, report and banner; throws ConfigError naming the value and the
  // limit.  `calibrating`: for a run that only calibrates the method's count.
  virtual void configure(const OptionValues& given, bool calibrating, MethodChoice& choice) const = 0;
  virtual std::unique_ptr<PressureMethod> make(const MethodChoice& choice, const MethodBuild& build) const = 0;
  // Bytes per rank beyond the Fields the method makes (those the memory model records
  // itself), for a local block of `local` cells on a `dims` rank grid.
  virtual double extra_bytes(const Int3& /*local*/, const Int3& /*dims*/) const { return 0.0; }
  // What those bytes hold, for the dry run ("FFT pencils and transposes").
  virtual std::string extra_bytes_hold() const { return name() + " solver"; }
  // For a method with a calibrated iteration count: what it counts, and a counter on
  // `decomp`; none (the default): the method has nothing to calibrate.
  virtual std::optional<CalibratedCount> calibrated_count() const { return std::nullopt; }
  virtual std::unique_ptr<IterationCounter> iteration_counter(const CartDecomposition&, const Domain&) const {
    return nullptr;
  }
  // One increment's work on a `global` grid split `dims` ways under `choice` (Crank-Nicolson
  // apart: the step counts its choice.cn_sweeps itself).
  virtual IncrementWork increment_work(const MethodChoice& choice, const Int3& global, const Int3& dims) const = 0;
};

}  // namespace efsi
