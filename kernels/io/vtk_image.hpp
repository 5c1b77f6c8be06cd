#pragma once
// Cell fields as VTK XML image data (.vti), which ParaView and VisIt open directly.
#include <string>
#include <utility>
#include <vector>

#include "domain.hpp"

namespace efsi {

// Writes `arrays` (name, global cell values x fastest then y then z) as cell data of one
// image covering the domain, raw little-endian Float64 in the appended section.
// Written whole or not at all (write_whole_file); throws std::runtime_error naming the file
// and the reason when it cannot be written.
void write_vti(const std::string& path, const Domain& domain,
               const std::vector<std::pair<std::string, const std::vector<double>*>>& arrays);

}  // namespace efsi
