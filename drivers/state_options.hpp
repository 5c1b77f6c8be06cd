#pragma once
// The options that write and read the solver's state, shared by every driver that runs
// steps: snapshots (parallel HDF5 + XDMF) and checkpoint/restart (docs/architecture.md,
// "Checkpoints").
#include <CLI/CLI.hpp>

#include <string>

namespace efsi {

struct RunRequest;

struct StateOptions {
  long checkpoint_every = 0, snapshot_every = 0;
  std::string checkpoint, restart, snapshot_prefix = "snapshot";
};

// --checkpoint, --checkpoint-every, --restart, --snapshot-every, --snapshot-prefix (its
// default `o.snapshot_prefix`).
void add_state_options(CLI::App& app, StateOptions& o);

// Checks the values (ConfigError naming the offending one) and copies them into `req`,
// with the checkpoint path `checkpoint.h5` when only --checkpoint-every names none.
// `tag` ("" for none) is inserted before the extension of each path (accuracy: one file per
// method).  Probes that the restart file can be read; run_case (check_outputs) probes that
// the outputs can be written.
void apply_state_options(const StateOptions& o, RunRequest& req, const std::string& tag = "");

}  // namespace efsi
