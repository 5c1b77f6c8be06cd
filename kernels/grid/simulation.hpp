#pragma once
// Whether this is the simulation build (EFSI_SIMGRID, the `simgrid` preset): the drivers
// compiled with SimGrid's smpicxx, run as simulated ranks under smpirun
// (harness/simgrid/README.md).
namespace efsi {

#ifdef EFSI_SIMGRID
inline constexpr bool kSimulated = true;
#else
inline constexpr bool kSimulated = false;
#endif

// Why the simulation build refuses the state files (checkpoints, snapshots, restarts).
inline constexpr const char* kNoHdf5InSimulation =
    "not in the simulation build: parallel HDF5 links Open MPI, not SimGrid's SMPI (checkpoints, snapshots and "
    "restarts need the release build)";

}  // namespace efsi
