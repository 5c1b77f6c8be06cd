// The simulation build (EFSI_SIMGRID) has no parallel HDF5: Debian's links Open MPI, not
// SimGrid's SMPI.  apply_state_options refuses --checkpoint and --restart there before a run
// starts; these keep the programs whole and say why, should a caller get here.
#include "checkpoint.hpp"
#include "config_error.hpp"
#include "simulation.hpp"

namespace efsi {

void write_checkpoint(const std::string& path, const ChannelCase&, const FsiSolver&, const RunHistory&,
                      const std::string&) {
  throw ConfigError("--checkpoint '" + path + "': " + kNoHdf5InSimulation);
}

CheckpointHeader check_checkpoint(const std::string& path, const ChannelCase&, const CartDecomposition&) {
  throw ConfigError("--restart '" + path + "': " + kNoHdf5InSimulation);
}

RunHistory restore_checkpoint(const std::string& path, FsiSolver&) {
  throw ConfigError("--restart '" + path + "': " + kNoHdf5InSimulation);
}

}  // namespace efsi
