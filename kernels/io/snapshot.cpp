#include "snapshot.hpp"

#include <cstdio>
#include <map>
#include <sstream>

#include "hdf5_file.hpp"
#include "text_file.hpp"

namespace efsi {
namespace {

std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string xmf_path(const std::string& h5_path) {
  const std::string stem = h5_path.size() > 3 && h5_path.ends_with(".h5") ? h5_path.substr(0, h5_path.size() - 3)
                                                                          : h5_path;
  return stem + ".xmf";
}

}  // namespace

std::string snapshot_name(const std::string& prefix, long step) {
  char b[32];
  std::snprintf(b, sizeof b, "-%08ld.h5", step);
  return prefix + b;
}

std::string xdmf_text(const std::string& h5_name, const std::vector<const Field*>& fields, const Domain& domain,
                      double time) {
  // One uniform grid per staggering, its points where the field's values live.
  std::map<Stagger, std::vector<const Field*>> by_stagger;
  for (const Field* f : fields) by_stagger[f->stagger()].push_back(f);
  std::ostringstream x;
  x.precision(17);
  x << "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
    << "  <Grid Name=\"fields\" GridType=\"Collection\" CollectionType=\"Spatial\">\n"
    << "   <Time Value=\"" << time << "\"/>\n";
  for (const auto& [stagger, members] : by_stagger) {
    int points[3];
    double origin[3];
    for (int a = 0; a < 3; ++a) {
      const bool face = is_staggered(stagger, a);
      points[a] = domain.cells[a] + (a == Y && face ? 1 : 0);
      origin[a] = face ? 0.0 : 0.5 * domain.spacing(a);
    }
    const std::string dims =
        std::to_string(points[Z]) + " " + std::to_string(points[Y]) + " " + std::to_string(points[X]);
    x << "   <Grid Name=\"" << to_string(stagger) << "\" GridType=\"Uniform\">\n"
      << "    <Topology TopologyType=\"3DCoRectMesh\" Dimensions=\"" << dims << "\"/>\n"
      << "    <Geometry GeometryType=\"ORIGIN_DXDYDZ\">\n"
      << "     <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">" << origin[Z] << ' '
      << origin[Y] << ' ' << origin[X] << "</DataItem>\n"
      << "     <DataItem Dimensions=\"3\" NumberType=\"Float\" Precision=\"8\" Format=\"XML\">" << domain.spacing(Z)
      << ' ' << domain.spacing(Y) << ' ' << domain.spacing(X) << "</DataItem>\n"
      << "    </Geometry>\n";
    for (const Field* f : members)
      x << "    <Attribute Name=\"" << f->name() << "\" AttributeType=\"Scalar\" Center=\"Node\">\n"
        << "     <DataItem Dimensions=\"" << dims << "\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">"
        << h5_name << ":/" << f->name() << "</DataItem>\n"
        << "    </Attribute>\n";
    x << "   </Grid>\n";
  }
  x << "  </Grid>\n </Domain>\n</Xdmf>\n";
  return x.str();
}

void write_snapshot(const std::string& h5_path, const std::vector<const Field*>& fields,
                    const CartDecomposition& decomp, const Domain& domain, long step, double time) {
  write_hdf5_atomically(h5_path, decomp, Hdf5File::bytes_needed(fields, decomp), [&](Hdf5File& file) {
    file.set_attribute("step", step);
    file.set_attribute("time", time);
    for (int a = 0; a < 3; ++a) {
      file.set_attribute(std::string("cells_") + "xyz"[a], long(domain.cells[a]));
      file.set_attribute(std::string("length_") + "xyz"[a], domain.length[a]);
    }
    for (const Field* f : fields) {
      file.write_field(f->name(), *f);
      file.set_attribute("stagger_" + f->name(), std::string(to_string(f->stagger())));
    }
  });
  int rank = 0;
  MPI_Comm_rank(decomp.comm(), &rank);
  std::string failure;
  if (rank == 0) try {
      write_text_file(xmf_path(h5_path), xdmf_text(base_name(h5_path), fields, domain, time));
    } catch (const std::exception& e) {
      failure = e.what();
    }
  agree_on_failure(decomp.comm(), failure);
}

}  // namespace efsi
