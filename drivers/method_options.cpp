#include "method_options.hpp"

#include <cmath>

#include <cstdio>
#include <initializer_list>
#include <string>
#include <utility>

#include "config_error.hpp"
#include "driver_support.hpp"
#include "runtime.hpp"

namespace efsi {

OptionValues MethodOptions::given() const {
  OptionValues v;
  for (const auto& [flag, value] : method_values)
    if (value) v[flag] = *value;
  return v;
}

std::string per_method(const std::function<std::string(const MethodSpec&)>& value) {
  std::string out;
  for (const MethodSpec* m : pressure_methods()) out += (out.empty() ? "" : ", ") + m->name() + ": " + value(*m);
  return out;
}

std::string scaling_dt_help() {
  return per_method([](const MethodSpec& m) { return format_value(m.scaling_defaults().dt); });
}

std::string scaling_steps_help() {
  return per_method([](const MethodSpec& m) { return std::to_string(m.scaling_defaults().steps); });
}

void add_reproducible_flag(CLI::App& app, bool& reproducible) {
  app.add_flag("--reproducible", reproducible,
               "choose no algorithm by timing it (fft: FFTW_ESTIMATE plans instead of FFTW_MEASURE), so that "
               "two runs of one case on one rank grid, or a run and its restart, give the same bits");
}

void add_method_options(CLI::App& app, MethodOptions& o, const std::string& dt_help) {
  std::string methods;
  for (const MethodSpec* m : pressure_methods()) methods += "\n  " + m->name() + ": " + m->summary();
  app.add_option("--method", o.method, "pressure method:" + methods)->capture_default_str();
  app.add_option("--comm", o.comm, "halo mode: sync | async")->capture_default_str();
  app.add_option("--halo", o.halo,
                 "how the exchanges that fill every ghost reach the edges and corners: direct (26 neighbours, "
                 "one round) | phased (6 faces, three rounds x, y, z); the same ghosts either way")
      ->capture_default_str();
  for (const RegisteredOption& r : registered_options()) {
    std::string takers;
    for (const std::string& t : r.methods) takers += (takers.empty() ? "" : ", ") + t;
    app.add_option(r.option.flag, o.method_values[r.option.flag], r.option.help + " (" + takers + " only)");
  }
  app.add_option("--nc", o.nc,
                 "Crank-Nicolson stress sweeps per step N_C (0: explicit stress; default: " +
                     per_method([](const MethodSpec& m) { return std::to_string(m.default_cn_sweeps()); }) + ")");
  app.add_option("--dt", o.dt, "time step (default: " + dt_help + ")");
  app.add_option("--threads", o.threads, "OpenMP threads per rank (default: OMP_NUM_THREADS)");
  std::string names;
  for (const Integrator& i : integrators()) names += (names.empty() ? "" : " | ") + i.name;
  app.add_option("--integrator", o.integrator, "time integrator: " + names)->capture_default_str();
  add_reproducible_flag(app, o.reproducible);
  app.add_flag_callback(
      "--list-methods",
      [] {
        if (is_root()) std::fputs(describe_methods().c_str(), stdout);
        throw CLI::Success();
      },
      "print the registered pressure methods and their options, one per line, and exit");
}

void check_time_step_value(double dt, const char* option) {
  if (!(dt > 0) || !std::isfinite(dt)) throw ConfigError(std::string(option) + " " + std::to_string(dt) + " must be a positive number");
}

void apply_physics_options(double G, double force, double solid_cutoff, ChannelCase& c) {
  if (!std::isfinite(G) || G < 0) throw ConfigError("--G " + std::to_string(G) + " must be zero or positive");
  if (!std::isfinite(force)) throw ConfigError("--force " + std::to_string(force) + " must be a finite number");
  if (!(solid_cutoff >= 0.0 && solid_cutoff < 1.0))
    throw ConfigError("--solid-cutoff " + std::to_string(solid_cutoff) + " must be at least 0 and below 1");
  c.solver.physics.G = G;
  c.solver.physics.force = force;
  c.solver.physics.solid_cutoff = solid_cutoff;
}

namespace {

// The value a keyword option names, or ConfigError naming the option, the word and the choices.
template <class Value>
Value keyword(const std::string& flag, const std::string& word,
              std::initializer_list<std::pair<const char*, Value>> choices) {
  std::string expected;
  std::size_t i = 0;
  for (const auto& [name, value] : choices) {
    if (word == name) return value;
    if (i > 0) expected += i + 1 == choices.size() ? " or " : ", ";
    expected += name;
    ++i;
  }
  throw ConfigError("unknown " + flag + " '" + word + "': expected " + expected);
}

}  // namespace

void apply_method_options(const MethodOptions& o, ChannelCase& c, double default_dt, bool calibrating) {
  c.solver.comm = keyword<CommMode>("--comm", o.comm, {{"sync", CommMode::sync}, {"async", CommMode::async}});
  c.solver.halo =
      keyword<HaloPattern>("--halo", o.halo, {{"direct", HaloPattern::direct}, {"phased", HaloPattern::phased}});
  choose_method(c, configure_method(o.method, o.given(), o.nc, calibrating));
  if (!c.method.spec->supports(c.solver.comm))
    throw ConfigError("--method " + o.method + " does not take --comm " + o.comm);
  if (o.threads < 0)
    throw ConfigError("--threads " + std::to_string(o.threads) + " must be positive (0: OMP_NUM_THREADS)");
  set_threads(o.threads);
  c.solver.integrator = find_integrator(o.integrator).name;
  c.timed_planning = !o.reproducible;
  c.solver.dt = o.dt.value_or(default_dt);
  check_time_step_value(c.solver.dt, "--dt");
}

long apply_scaling_defaults(const MethodOptions& o, ChannelCase& c, std::optional<long> steps) {
  const ScalingDefaults d = find_method(o.method).scaling_defaults();
  apply_method_options(o, c, d.dt);
  const long n = steps.value_or(d.steps);
  if (n < 1) throw ConfigError("--steps " + std::to_string(n) + " must be at least 1");
  return n;
}

}  // namespace efsi
