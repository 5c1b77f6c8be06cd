#pragma once
// One CSV row per finished run (docs/numerics.md, "Output: the CSV run record"), appended by rank 0 under an
// exclusive file lock so that concurrent runs never interleave or lose a row.
#include <mpi.h>

#include <string>
#include <vector>

#include "hybrid_layout.hpp"
#include "region_timers.hpp"

namespace efsi {

struct RunRecord {
  std::string experiment, method, comm, eps;  // eps empty where it does not apply
  int ranks = 1, threads = 1;
  int px = 1, py = 1, pz = 1;
  int nx = 0, ny = 0, nz = 0;
  long particles = 0, steps = 0;
  double dt = 0;
  std::string ns_per_step, nc_per_step;  // empty where they do not apply
  std::string integrator = "euler";
  double pressure_iterations = 0;   // mean iterations per solve (SOR sweeps, V-cycles); 0: none (empty cell)
  double pressure_setup_s = 0;      // the method's set-up, outside the measured steps
  TimerReport timing;
  double div_rms = 0;
  bool valid = false;
  HybridLayout layout;  // an oversubscribed run is never written as valid
  std::string halo = "direct";  // SolverConfig::halo
  std::string simulated;  // the platform of a simulation-build run; "" for a measured one
  // Point-to-point messages and their bytes in a measured step, summed over the ranks.
  double mpi_messages_per_step = 0, mpi_bytes_per_step = 0;
  std::string sweeps_per_exchange;  // SOR's temporal blocking K; empty where it does not apply
};

// The git revision the programs were built from ("unknown" outside a git checkout).
std::string build_revision();

// The section-8 columns in order, then the suite's own: oversubscribed, omp_num_threads,
// omp_places, omp_proc_bind, cores (hybrid_layout.hpp), integrator, pressure_iterations,
// pressure_setup_s, cores_shared, simulated, mpi_messages_per_step, mpi_bytes_per_step, halo,
// sweeps_per_exchange.
const std::vector<std::string>& csv_columns();
std::string csv_header();  // the columns joined by commas, no newline

// Fills host, MPI library, compiler, git revision and UTC timestamp, and formats the row.
std::string csv_row(const RunRecord& r);

// Appends the row (and the header when the file is new or empty) atomically with respect
// to other processes using the same function. Throws std::runtime_error naming the file
// when it cannot be written.
void append_csv(const std::string& path, const RunRecord& r);

// Collective over MPI_COMM_WORLD, before a run: --csv PATH can be written (check_writable)
// and, when it already holds a header, it is this build's, so that the rows line up;
// ConfigError naming the path otherwise.  An empty path passes.
void check_csv(const std::string& path);

}  // namespace efsi
