#pragma once
// Checkpoint and restart of a channel run (docs/architecture.md, "Checkpoints"): one
// parallel HDF5 file with every state field as a global dataset, the step and time, the
// configuration it was run with, the pressure method's last report, the code's revision,
// and the run's output rows so far.  The datasets do not depend on the decomposition, so a
// run restarts on any rank count; on the same one it continues bitwise.
#include <string>
#include <utility>
#include <vector>

#include "channel_case.hpp"

namespace efsi {

// What a run carries across a restart besides the solver's state: the series and centroid
// rows it recorded so far (so that the files written at the end cover the whole run).
struct RunHistory {
  std::string series, centroids;
};

// Everything that must match for a checkpoint to continue this case, as (name, value)
// with values printed exactly (%.17g): cells, lengths, method and its settings, N_C,
// physics, dt, integrator, particles, slab.  Not the halo mode: sync and async step alike.
std::vector<std::pair<std::string, std::string>> checkpoint_configuration(const ChannelCase& c);

// Writes the checkpoint under a temporary name and renames it when complete (a run killed
// while writing leaves the previous checkpoint).  Collective; OutputError on every rank.
void write_checkpoint(const std::string& path, const ChannelCase& c, const FsiSolver& solver,
                      const RunHistory& history, const std::string& revision);

struct CheckpointHeader {
  long step = 0;
  double time = 0.0;
  std::string revision;
};

// Opens `path` and compares its configuration with `c`: ConfigError naming the first
// difference ("--restart 'F' was written with dt = 1.25e-05; this run has dt = 6.25e-05"),
// OutputError when it cannot be read.  Reads no field: call it before allocating.  Collective.
CheckpointHeader check_checkpoint(const std::string& path, const ChannelCase& c, const CartDecomposition& decomp);

// Sets the solver's state, step and time from the checkpoint (already checked) and returns
// the run's rows so far.  Collective.
RunHistory restore_checkpoint(const std::string& path, FsiSolver& solver);

}  // namespace efsi
