#pragma once
// The simulation build's compute model (harness/simgrid/README.md).  A stage's loops do not
// run there: the stage charges the time a modelled core takes for the work counted from its
// code (work_count.hpp), while the halo exchanges, reductions and transposes around it run
// through the project's own code under SMPI, with their real sizes and counts.  The model
// is a roofline per rank, over the efficiency calibrated for the run's method:
//
//   t = max(flops / F, bytes / min(C, (B / S) / ranks on the socket)) / e
//
// F: the platform host's speed (one core, flop/s); B: the host's property memory_bandwidth
// (B/s, the whole node); S: its property sockets (1 when absent), each with its own share
// of B, the node's ranks filling them in order (Open MPI's by-core placement); C: its
// property core_bandwidth (B/s one core draws alone: a core reaches a fraction of its
// node's bandwidth; unlimited when absent); e: the host's property efficiency:<method>, 1
// when absent, or, for an iterative solver's sweeps (sweep_stage), efficiency:<method>-sweeps
// when the host has it: a sweep's few flops a cell over memory reach another fraction of
// the roofline than the step's stencils, and one-core times at two tolerances tell the two
// apart (harness/simgrid/calibrate.py).  In the
// real build the loops run and nothing is charged.  The platform files and their
// calibration: harness/simgrid/README.md.
#include <string>

#include "simulation.hpp"
#include "work_count.hpp"

namespace efsi {

// What the model charges with; all zero in the real build.
struct NodeModel {
  std::string platform;      // the host's property platform (the CSV's `simulated`), else its name
  std::string host;          // the platform host this rank runs on
  double core_flops = 0;     // F
  double node_bandwidth = 0; // B
  double core_bandwidth = 0; // C
  int ranks_on_node = 0;
  int cores_on_node = 0;     // the host's core count
  int sockets = 1;           // S
  int ranks_on_socket = 0;   // this rank's socket's
  double efficiency = 0;     // e, for the method chosen last
  double sweep_efficiency = 0;  // e of its solver's sweeps
};

// Collective over MPI_COMM_WORLD in the simulation build (the ranks on each node); reads the
// host's speed and bandwidth, and refuses (ConfigError) a host without memory_bandwidth.
// Nothing in the real build.  Runtime calls it after MPI_Init.
void init_compute_model();
// Takes the efficiency of `method` from the host (efficiency:<method>; 1 when absent).
void use_efficiency_of(const std::string& method);
const NodeModel& node_model();

// Charges `cells` cells of `cost` as this rank's compute time (simulation build only), at
// the step's efficiency or at the sweeps'.
enum class Efficiency { step, sweeps };
void charge_compute(PerCell cost, double cells, Efficiency e = Efficiency::step);

// A stage's loops in the real build; their modelled time in the simulation build.
template <class Loops>
inline void compute_stage(PerCell cost, double cells, Loops&& loops) {
  if constexpr (kSimulated) charge_compute(cost, cells);
  else loops();
}

// An iterative solver's sweep: as compute_stage, charged at the sweeps' efficiency.
template <class Loops>
inline void sweep_stage(PerCell cost, double cells, Loops&& loops) {
  if constexpr (kSimulated) charge_compute(cost, cells, Efficiency::sweeps);
  else loops();
}

// A set-up fill of the initial state: runs in the real build.  The simulation build skips
// it: its fields are folded onto shared pages and hold no state, set-up is not timed, and
// touching those pages cost the simulator most of its set-up (page faults on the folded
// mappings, 8192 ranks' worth).
template <class Loops>
inline void setup_stage(Loops&& loops) {
  if constexpr (!kSimulated) loops();
}

}  // namespace efsi
