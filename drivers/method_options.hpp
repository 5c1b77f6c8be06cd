#pragma once
// The options that choose and tune the pressure method (DESIGN.md section 8), shared by
// channel, weak_scaling and strong_scaling so that they parse and check them alike.
#include <CLI/CLI.hpp>

#include <optional>
#include <string>

#include "channel_case.hpp"

namespace efsi {

struct MethodOptions {
  std::string method = "acm", comm = "sync", integrator = "euler";
  std::optional<double> eps, dt;
  std::optional<int> ns, nc;
  int threads = 0;
};

// --method, --comm, --eps, --ns, --nc, --dt, --threads, --integrator. `dt_help` names the default.
void add_method_options(CLI::App& app, MethodOptions& o, const std::string& dt_help);

// Checks the values and fills c.method, c.solver.comm, c.solver.cn_sweeps (default 20 for
// sor, the paper's N_C; 0 otherwise), c.sor_sweeps (--ns, else the calibrated count for
// --eps) and c.solver.dt (--dt, else `default_dt`). `calibrating`: N_S is not needed.
// Throws ConfigError naming the offending value.
void apply_method_options(const MethodOptions& o, ChannelCase& c, double default_dt, bool calibrating = false);

// The scaling experiments' defaults (DESIGN.md section 5): ACM 50 steps of 1.25e-5; SOR
// and the FFT reference 10 steps of 6.25e-5. Applies the options as above and returns the
// measured steps (`steps` when given). Throws ConfigError for fewer than one step.
long apply_scaling_defaults(const MethodOptions& o, ChannelCase& c, std::optional<long> steps);

// The CSV's eps cell: the eps that chose N_S, "" when --ns set it or the method is not sor.
std::string eps_cell(const MethodOptions& o, const ChannelCase& c);

}  // namespace efsi
