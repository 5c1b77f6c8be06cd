#pragma once
// Snapshots of fields at chosen steps: one parallel HDF5 file of global datasets
// (hdf5_file.hpp) and an XDMF description beside it, so that ParaView or VisIt open it as
// uniform grids with each staggering at its own points (a field on x faces starts at x = 0,
// a cell field at half a cell).
#include <string>
#include <vector>

#include "decomposition.hpp"
#include "domain.hpp"
#include "field.hpp"

namespace efsi {

// PREFIX-STEP.h5 with eight digits of step (the name ParaView groups as a time series).
std::string snapshot_name(const std::string& prefix, long step);

// Writes `h5_path` (each field under its own name, attributes step, time, cells, lengths)
// and the same path with .xmf for .h5.  Collective; OutputError on every rank on failure.
void write_snapshot(const std::string& h5_path, const std::vector<const Field*>& fields,
                    const CartDecomposition& decomp, const Domain& domain, long step, double time);

// The XDMF text for such a file (the name inside is `h5_name`, relative to the .xmf).
std::string xdmf_text(const std::string& h5_name, const std::vector<const Field*>& fields, const Domain& domain,
                      double time);

}  // namespace efsi
