// The simulation build (EFSI_SIMGRID) has no parallel HDF5: Debian's links Open MPI, not
// SimGrid's SMPI.  apply_state_options refuses --snapshot-every there before a run starts;
// these keep the programs whole and say why, should a caller get here.
#include "config_error.hpp"
#include "simulation.hpp"
#include "snapshot.hpp"

namespace efsi {

std::string snapshot_name(const std::string& prefix, long) {
  throw ConfigError("--snapshot-prefix '" + prefix + "': " + kNoHdf5InSimulation);
}

void write_snapshot(const std::string& h5_path, const std::vector<const Field*>&, const CartDecomposition&,
                    const Domain&, long, double) {
  throw ConfigError("snapshot '" + h5_path + "': " + kNoHdf5InSimulation);
}

}  // namespace efsi
