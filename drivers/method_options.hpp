#pragma once
// The options that choose and tune the pressure method and the time stepping, shared by
// channel, weak_scaling, strong_scaling and accuracy so that they parse and check them
// alike.  The methods and their own options come from the registry (method_registry.hpp).
#include <CLI/CLI.hpp>

#include <functional>
#include <map>
#include <optional>
#include <string>

#include "channel_case.hpp"
#include "method_spec.hpp"

namespace efsi {

struct MethodOptions {
  std::string method = "acm", comm = "sync", integrator = "euler", halo = "direct";
  std::map<std::string, std::optional<double>> method_values;  // by flag, one per registered option
  std::optional<double> dt;
  std::optional<int> nc;
  int threads = 0;
  bool reproducible = false;  // no algorithm chosen by timing (ChannelCase::timed_planning off)

  OptionValues given() const;  // the method options given on the command line
};

// --method, --comm, --halo, every registered method's options, --nc, --dt, --threads, --integrator,
// --reproducible.
// `dt_help` names the default.
void add_method_options(CLI::App& app, MethodOptions& o, const std::string& dt_help);

// --reproducible alone, for a driver that chooses its methods otherwise (accuracy).
void add_reproducible_flag(CLI::App& app, bool& reproducible);

// "acm: 50, fft: 10, sor: 10": one value per registered method, for help texts.
std::string per_method(const std::function<std::string(const MethodSpec&)>& value);
// The scaling drivers' defaults of --dt and --steps, per method.
std::string scaling_dt_help();
std::string scaling_steps_help();

// Checks the values and fills c.method (with c.solver.cn_sweeps), c.solver.comm,
// c.solver.integrator and c.solver.dt (--dt, else `default_dt`), and sets the threads.
// `calibrating`: the method is set up only to be calibrated.  Throws ConfigError naming the
// offending value.
void apply_method_options(const MethodOptions& o, ChannelCase& c, double default_dt, bool calibrating = false);

// The scaling experiments' defaults, the method's (MethodSpec::scaling_defaults: the paper's
// ACM 50 steps of 1.25e-5, SMAC 10 of 6.25e-5). Applies the options as above and returns the
// measured steps (`steps` when given). Throws ConfigError for fewer than one step.
long apply_scaling_defaults(const MethodOptions& o, ChannelCase& c, std::optional<long> steps);

// A positive, finite time step; throws ConfigError naming `option` and the value.
void check_time_step_value(double dt, const char* option);

// --G (zero or positive), --force (finite) and --solid-cutoff (0 to below 1) into
// c.solver.physics; throws ConfigError naming the option and the value.
void apply_physics_options(double G, double force, double solid_cutoff, ChannelCase& c);

}  // namespace efsi
