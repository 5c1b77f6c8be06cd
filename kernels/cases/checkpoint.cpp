#include "checkpoint.hpp"

#include <charconv>

#include "config_error.hpp"
#include "hdf5_file.hpp"

namespace efsi {
namespace {

// The shortest text that reads back as the same double: equal texts, equal values.
std::string exact(double v) {
  char b[40];
  const auto end = std::to_chars(b, b + sizeof b, v).ptr;
  return std::string(b, end);
}

std::string exact3(const std::array<double, 3>& v) { return exact(v[0]) + "," + exact(v[1]) + "," + exact(v[2]); }

const std::string kConfig = "config ";  // attribute prefix of the configuration's entries

}  // namespace

std::vector<std::pair<std::string, std::string>> checkpoint_configuration(const ChannelCase& c) {
  const Int3& n = c.domain.cells;
  std::vector<std::pair<std::string, std::string>> out = {
      {"cells", std::to_string(n[0]) + "," + std::to_string(n[1]) + "," + std::to_string(n[2])},
      {"length", exact3(c.domain.length)},
      {"method", c.method.name()},
  };
  for (const auto& [key, value] : c.method.values) out.emplace_back(c.method.name() + " " + key, exact(value));
  const Physics& ph = c.solver.physics;
  out.insert(out.end(), {{"N_C", std::to_string(c.solver.cn_sweeps)},
                         {"G", exact(ph.G)},
                         {"force", exact(ph.force)},
                         {"rho", exact(ph.rho)},
                         {"mu", exact(ph.mu)},
                         {"solid cutoff", exact(ph.solid_cutoff)},
                         {"dt", exact(c.solver.dt)},
                         {"integrator", c.solver.integrator},
                         {"particles", std::to_string(c.particles)},
                         {"particle diameter", exact(c.particle.diameter)},
                         {"particle lattice", exact(c.particle.lattice)},
                         {"particle tilt", exact(c.particle.max_tilt_deg)},
                         {"particle seed", std::to_string(c.particle.seed)},
                         {"slab", exact(c.slab)}});
  return out;
}

void write_checkpoint(const std::string& path, const ChannelCase& c, const FsiSolver& solver,
                      const RunHistory& history, const std::string& revision) {
  const std::vector<const Field*> fields = solver.state().all();
  const std::size_t bytes =
      Hdf5File::bytes_needed(fields, solver.state().decomp(), history.series.size() + history.centroids.size());
  write_hdf5_atomically(path, solver.state().decomp(), bytes, [&](Hdf5File& file) {
    file.set_attribute("step", solver.steps_done());
    file.set_attribute("time", solver.time());
    file.set_attribute("revision", revision);
    for (const auto& [key, value] : checkpoint_configuration(c)) file.set_attribute(kConfig + key, value);
    // The method's last choice, for the record: its state proper is p (a field) and its
    // settings (the configuration).
    const PressureReport& r = solver.pressure().report();
    file.set_attribute("pressure beta", r.beta);
    file.set_attribute("pressure gamma", r.gamma);
    file.set_attribute("pressure iterations", long(r.sweeps));
    for (const Field* f : fields) file.write_field(f->name(), *f);
    file.write_text("series", history.series);
    file.write_text("centroids", history.centroids);
  });
}

namespace {

// The header and the configuration check; OutputError where the file cannot be read.
CheckpointHeader read_header(const std::string& path, const ChannelCase& c, const CartDecomposition& decomp) {
  Hdf5File file(path, Hdf5File::Mode::read, decomp);
  CheckpointHeader h;
  if (!file.has_attribute("step") || !file.has_attribute(kConfig + "method"))
    throw ConfigError("--restart '" + path + "' is not a checkpoint of this program");
  h.step = file.long_attribute("step");
  h.time = file.double_attribute("time");
  h.revision = file.string_attribute("revision");
  for (const auto& [key, value] : checkpoint_configuration(c)) {
    const std::string theirs =
        file.has_attribute(kConfig + key) ? file.string_attribute(kConfig + key) : std::string("(none)");
    if (theirs != value)
      throw ConfigError("--restart '" + path + "' was written with " + key + " = " + theirs + "; this run has " +
                        key + " = " + value);
  }
  file.close();
  return h;
}

}  // namespace

CheckpointHeader check_checkpoint(const std::string& path, const ChannelCase& c, const CartDecomposition& decomp) {
  try {
    return read_header(path, c, decomp);
  } catch (const OutputError& e) {
    throw ConfigError("--restart '" + path + "' is not a readable checkpoint (" + e.what() + ")");
  }
}

RunHistory restore_checkpoint(const std::string& path, FsiSolver& solver) {
  FsiState& s = solver.state();
  Hdf5File file(path, Hdf5File::Mode::read, s.decomp());
  for (Field* f : s.all()) file.read_field(f->name(), *f);
  RunHistory h{file.read_text("series"), file.read_text("centroids")};
  const long step = file.long_attribute("step");
  const double time = file.double_attribute("time");
  file.close();
  solver.resume(step, time);
  return h;
}

}  // namespace efsi
