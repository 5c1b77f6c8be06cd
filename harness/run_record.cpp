#include "run_record.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "config_error.hpp"
#include "text_file.hpp"

#ifndef EFSI_GIT_SHA
#define EFSI_GIT_SHA "unknown"
#endif

namespace efsi {
namespace {

std::string host_name() {
  char buf[256] = "";
  gethostname(buf, sizeof buf - 1);
  return buf;
}

std::string mpi_library() {
  char buf[MPI_MAX_LIBRARY_VERSION_STRING] = "";
  int len = 0;
  MPI_Get_library_version(buf, &len);
  std::string s(buf, static_cast<std::size_t>(len));
  const auto cut = s.find_first_of(",\n");
  return s.substr(0, cut);
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

// No commas or newlines may reach a cell.
std::string clean(std::string s) {
  for (char& c : s)
    if (c == ',' || c == '\n' || c == '\r') c = ' ';
  return s;
}

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

std::string build_revision() { return EFSI_GIT_SHA; }

const std::vector<std::string>& csv_columns() {
  static const std::vector<std::string> cols = {"experiment",
                                                "method",
                                                "comm",
                                                "eps",
                                                "ranks",
                                                "threads",
                                                "px",
                                                "py",
                                                "pz",
                                                "nx",
                                                "ny",
                                                "nz",
                                                "particles",
                                                "steps",
                                                "dt",
                                                "ns_per_step",
                                                "nc_per_step",
                                                "elapsed_s",
                                                "compute_s",
                                                "halo_s",
                                                "reduce_s",
                                                "comm_s",
                                                "comm_s_max",
                                                "comm_fraction",
                                                "mlups",
                                                "div_rms",
                                                "valid",
                                                "host",
                                                "mpi",
                                                "compiler",
                                                "git_sha",
                                                "timestamp",
                                                "oversubscribed",
                                                "omp_num_threads",
                                                "omp_places",
                                                "omp_proc_bind",
                                                "cores",
                                                "integrator",
                                                "pressure_iterations",
                                                "pressure_setup_s",
                                                "cores_shared",
                                                "simulated",
                                                "mpi_messages_per_step",
                                                "mpi_bytes_per_step",
                                                "halo",
                                                "sweeps_per_exchange"};
  return cols;
}

std::string csv_row(const RunRecord& r) {
  const TimerReport& t = r.timing;
  const double halo_mean =
      t[Region::halo_pack].mean + t[Region::halo_unpack].mean + t[Region::halo_mpi].mean + t[Region::halo_wait].mean;
  const double cells = double(r.nx) * r.ny * r.nz;
  const double mlups = t.elapsed.max > 0 ? cells * double(r.steps) / t.elapsed.max / 1e6 : 0.0;
  std::ostringstream o;
  o << clean(r.experiment) << ',' << clean(r.method) << ',' << clean(r.comm) << ',' << clean(r.eps) << ',' << r.ranks
    << ',' << r.threads << ',' << r.px << ',' << r.py << ',' << r.pz << ',' << r.nx << ',' << r.ny << ',' << r.nz << ','
    << r.particles << ',' << r.steps << ',' << num(r.dt) << ',' << clean(r.ns_per_step) << ',' << clean(r.nc_per_step)
    << ',' << num(t.elapsed.max) << ',' << num(t[Region::compute].mean) << ',' << num(halo_mean) << ','
    << num(t[Region::reduce].mean) << ',' << num(t.comm.mean) << ',' << num(t.comm.max) << ',' << num(t.comm_fraction)
    << ',' << num(mlups) << ',' << num(r.div_rms) << ',' << (r.valid && !r.layout.oversubscribed ? 1 : 0) << ','
    << clean(host_name()) << ',' << clean(mpi_library()) << ',' << clean("g++ " __VERSION__) << ','
    << clean(build_revision()) << ',' << utc_now() << ',' << (r.layout.oversubscribed ? 1 : 0) << ','
    << clean(r.layout.omp_num_threads) << ',' << clean(r.layout.omp_places) << ',' << clean(r.layout.omp_proc_bind)
    << ',' << clean(r.layout.cores) << ',' << clean(r.integrator) << ',' << (r.pressure_iterations > 0 ? num(r.pressure_iterations) : std::string()) << ','
    << num(r.pressure_setup_s) << ',' << (r.layout.cores_shared ? 1 : 0) << ',' << clean(r.simulated) << ','
    << num(r.mpi_messages_per_step) << ',' << num(r.mpi_bytes_per_step) << ',' << clean(r.halo) << ','
    << clean(r.sweeps_per_exchange) << '\n';
  return o.str();
}

void append_csv(const std::string& path, const RunRecord& r) { append_locked(path, csv_header() + '\n', csv_row(r)); }

std::string csv_header() {
  std::string header;
  for (const auto& c : csv_columns()) header += (header.empty() ? "" : ",") + c;
  return header;
}

void check_csv(const std::string& path) {
  check_writable(path, "--csv");
  if (path.empty()) return;
  int rank = 0, other_columns = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  if (rank == 0) {
    std::ifstream in(path);
    std::string first;
    if (in && std::getline(in, first) && !first.empty() && first != csv_header())
      other_columns = static_cast<int>(std::count(first.begin(), first.end(), ',')) + 1;
  }
  MPI_Bcast(&other_columns, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (other_columns > 0)
    throw ConfigError("--csv '" + path + "' has another header (" + std::to_string(other_columns) +
                      " columns, this build writes " + std::to_string(csv_columns().size()) +
                      "): its rows would not line up; append to a new file");
}

}  // namespace efsi
