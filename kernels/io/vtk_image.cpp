#include "vtk_image.hpp"

#include <bit>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace efsi {

void write_vti(const std::string& path, const Domain& domain,
               const std::vector<std::pair<std::string, const std::vector<double>*>>& arrays) {
  static_assert(std::endian::native == std::endian::little, "the writer declares LittleEndian");
  const Int3& n = domain.cells;
  std::ostringstream head;
  head.precision(17);
  head << "<?xml version=\"1.0\"?>\n"
       << "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
       << "  <ImageData WholeExtent=\"0 " << n[0] << " 0 " << n[1] << " 0 " << n[2] << "\" Origin=\"0 0 0\" Spacing=\""
       << domain.spacing(0) << ' ' << domain.spacing(1) << ' ' << domain.spacing(2) << "\">\n"
       << "    <Piece Extent=\"0 " << n[0] << " 0 " << n[1] << " 0 " << n[2] << "\">\n"
       << "      <CellData Scalars=\"" << (arrays.empty() ? "" : arrays[0].first) << "\">\n";
  std::uint64_t offset = 0;
  for (const auto& [name, values] : arrays) {
    if (values->size() != static_cast<std::size_t>(product(n)))
      throw std::runtime_error("write_vti: array " + name + " does not match the grid");
    head << "        <DataArray type=\"Float64\" Name=\"" << name << "\" format=\"appended\" offset=\"" << offset
         << "\"/>\n";
    offset += sizeof(std::uint64_t) + values->size() * sizeof(double);
  }
  head << "      </CellData>\n    </Piece>\n  </ImageData>\n  <AppendedData encoding=\"raw\">\n   _";

  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f << head.str();
  for (const auto& [name, values] : arrays) {
    const std::uint64_t bytes = values->size() * sizeof(double);
    f.write(reinterpret_cast<const char*>(&bytes), sizeof bytes);
    f.write(reinterpret_cast<const char*>(values->data()), static_cast<std::streamsize>(bytes));
  }
  f << "\n  </AppendedData>\n</VTKFile>\n";
  if (!f) throw std::runtime_error("cannot write " + path);
}

}  // namespace efsi
