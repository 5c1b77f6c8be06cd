#include "vtk_image.hpp"

#include <bit>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "text_file.hpp"

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

  // Each array is preceded by its size in bytes; the pieces point into `sizes` and the
  // arrays, so the image is never copied into one buffer.
  std::vector<std::uint64_t> sizes;
  sizes.reserve(arrays.size());
  const std::string head_text = head.str();
  std::vector<std::string_view> pieces{head_text};
  for (const auto& [name, values] : arrays) {
    sizes.push_back(values->size() * sizeof(double));
    pieces.emplace_back(reinterpret_cast<const char*>(&sizes.back()), sizeof(std::uint64_t));
    pieces.emplace_back(reinterpret_cast<const char*>(values->data()), sizes.back());
  }
  pieces.emplace_back("\n  </AppendedData>\n</VTKFile>\n");
  write_whole_file(path, pieces);
}

}  // namespace efsi
