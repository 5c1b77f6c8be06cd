#include "state_options.hpp"

#include <unistd.h>

#include "case_run.hpp"
#include "config_error.hpp"
#include "simulation.hpp"

namespace efsi {
namespace {

// "run/ck.h5" with tag "acm" -> "run/ck-acm.h5".
std::string tagged(const std::string& path, const std::string& tag) {
  if (tag.empty() || path.empty()) return path;
  const auto slash = path.find_last_of('/');
  const auto dot = path.find_last_of('.');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return path + "-" + tag;
  return path.substr(0, dot) + "-" + tag + path.substr(dot);
}

}  // namespace

void add_state_options(CLI::App& app, StateOptions& o) {
  app.add_option("--checkpoint", o.checkpoint,
                 "write the run's state to this HDF5 file at the end (and every --checkpoint-every steps), "
                 "under a temporary name renamed when complete");
  app.add_option("--checkpoint-every", o.checkpoint_every,
                 "steps between checkpoints (default file: checkpoint.h5); 0: none")
      ->capture_default_str();
  app.add_option("--restart", o.restart,
                 "continue the run from this checkpoint, on any rank count; its configuration must be this "
                 "run's; --steps and --t-end count from the start of the whole run; with --reproducible on both parts and "
                 "the same rank grid it ends on the bits of the uninterrupted run");
  app.add_option("--snapshot-every", o.snapshot_every,
                 "steps between snapshots of every state field: PREFIX-STEP.h5 (parallel HDF5) and .xmf "
                 "(ParaView); 0: none")
      ->capture_default_str();
  app.add_option("--snapshot-prefix", o.snapshot_prefix,
                 "path prefix of the snapshots" + (o.snapshot_prefix.empty() ? std::string(" (default: OUT/snapshot)")
                                                                              : " (default: " + o.snapshot_prefix + ")"));
}

void apply_state_options(const StateOptions& o, RunRequest& req, const std::string& tag) {
  if (o.checkpoint_every < 0)
    throw ConfigError("--checkpoint-every " + std::to_string(o.checkpoint_every) + " must be zero or positive");
  if (o.snapshot_every < 0)
    throw ConfigError("--snapshot-every " + std::to_string(o.snapshot_every) + " must be zero or positive");
  if (o.snapshot_every > 0 && o.snapshot_prefix.empty()) throw ConfigError("--snapshot-prefix '' names no file");
  if (kSimulated) {
    const char* asked = !o.restart.empty()              ? "--restart"
                        : o.snapshot_every > 0          ? "--snapshot-every"
                        : !o.checkpoint.empty() || o.checkpoint_every > 0 ? "--checkpoint"
                                                                          : nullptr;
    if (asked) throw ConfigError(std::string(asked) + ": " + kNoHdf5InSimulation);
  }
  req.checkpoint = tagged(o.checkpoint.empty() && o.checkpoint_every > 0 ? "checkpoint.h5" : o.checkpoint, tag);
  req.checkpoint_every = o.checkpoint_every;
  req.restart = tagged(o.restart, tag);
  req.snapshots = o.snapshot_every > 0 ? tagged(o.snapshot_prefix, tag) : std::string();
  req.snapshot_every = o.snapshot_every;
  if (!req.restart.empty() && ::access(req.restart.c_str(), R_OK) != 0) {
    // A driver that runs several methods keeps one checkpoint per method; the name it derived
    // is told, or passing the file one sees on disk gives an error about a file one never named.
    if (req.restart != o.restart)
      throw ConfigError("--restart '" + o.restart + "': the checkpoint of method " + tag + " is '" + req.restart +
                        "' (the name given with -" + tag + " added), which cannot be read");
    throw ConfigError("--restart '" + req.restart + "' cannot be read");
  }
}

}  // namespace efsi
