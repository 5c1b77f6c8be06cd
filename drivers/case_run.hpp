#pragma once
// One measured run of a channel case, shared by every driver: set-up banner, warm-up
// step, the timed steps, the validation phase (its failure invalidates the timing, as in
// HPCG and NPB), the section-7 timing report, optional outputs and the section-8 CSV row.
#include <memory>
#include <string>
#include <vector>

#include "channel_case.hpp"
#include "run_record.hpp"
#include "state_options.hpp"
#include "text_file.hpp"

namespace efsi {

struct RunRequest {
  std::string program;      // for the banner
  std::string experiment;   // the CSV's experiment column
  long total_steps = 2;     // one warm-up step, then total_steps - 1 measured ones
  int every = 10;           // steps between series and centroid rows
  int progress = 0;         // print progress every N steps (0: 20 times in long runs)
  // Optional outputs; "" for none. Written by rank 0 only after the run finished, the CSV
  // row last and only when the others were written.
  std::string series, centroids, profile, csv;
  // --force-memory: run even when the memory estimate exceeds the node's MemAvailable.
  bool force_memory = false;
  // The caller ran check_node_memory itself (accuracy: for all its methods at once).
  bool memory_checked = false;
  // The solver's state (state_options.hpp): a checkpoint at the end and every
  // checkpoint_every steps, snapshots PREFIX-STEP.h5 every snapshot_every steps, and the
  // checkpoint to continue from.  Written between steps, outside the measured time.
  std::string checkpoint, snapshots, restart;
  long checkpoint_every = 0, snapshot_every = 0;
};

struct RunOutcome {
  bool valid = false;                  // finite, divergence and energy budget in bounds
  // Declared before the solver, which refers to it: members are destroyed in reverse order.
  std::unique_ptr<CartDecomposition> decomp;
  std::unique_ptr<FsiSolver> solver;   // the final state, for drivers that write fields
  RunRecord record;                    // the CSV row, for drivers that append it themselves
};

// Collective over MPI_COMM_WORLD: every output the request names can be created where it
// will be written (check_writable), or ConfigError naming the option and the path.
void check_outputs(const RunRequest& req);

// Collective over MPI_COMM_WORLD. Checks that every output is writable (check_outputs) and that the node
// holds the solver (check_node_memory) before allocating; throws OutputError on every rank
// when one cannot be written after the run.  `particles`: the whole lattice; each rank keeps
// those that reach its block (particles_reaching) once its block is known.
RunOutcome run_case(const ChannelCase& c, const std::vector<Particle>& particles, const RunRequest& req);
// The same with the case's own lattice (case_particles), built by each rank once its block
// is known and trimmed before its next MPI call.
RunOutcome run_case(const ChannelCase& c, const RunRequest& req);

// The scaling drivers' run: validates the case (ConfigError before anything is
// allocated), runs one warm-up and `steps` measured steps and appends the row to `csv`
// ("" for none); `force_memory` as in RunRequest. Returns the exit status: 0 when the run's
// checks passed, 4 otherwise.
int run_scaling_case(const ChannelCase& c, const std::string& program, const std::string& experiment, long steps,
                     const std::string& csv, bool force_memory, const StateOptions& state);

}  // namespace efsi
