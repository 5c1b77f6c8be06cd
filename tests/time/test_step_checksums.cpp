// Bitwise reference of whole steps: a checksum of every state field after 20 steps of each
// pressure method in both halo modes, on 2 ranks, compared with the checksums recorded in
// tests/time/data/step_checksums.txt.  The fields must not change by one bit under a change that
// only reorganises the code (a refactoring, a new integrator beside explicit Euler); a change
// that is meant to round differently records new checksums, deliberately:
//   EFSI_WRITE_CHECKSUMS=tests/time/data/step_checksums.txt mpirun -n 2 build/bin/test_step_checksums
// The set-up: the paper's block (3.6^3, 2 particles) per rank at 32^3, ranks side by side in
// x, G = 50, started in the laminar Poiseuille flow, FFT plans by estimate (a measured plan
// may round differently).
#include <gtest/gtest.h>
#include <mpi.h>

#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "channel_case.hpp"
#include "mpi_test_support.hpp"

namespace efsi {
namespace {

constexpr int kSteps = 20;
constexpr int kBlock = 32;

struct Case {
  std::string method;
  CommMode mode;
  double dt;
  int ns, nc;
};

std::string case_name(const Case& c) { return c.method + "/" + to_string(c.mode); }

// FNV-1a over the bit patterns of the owned values, x fastest.
std::uint64_t field_hash(const Field& f) {
  std::uint64_t h = 1469598103934665603ull;
  const Int3 n = f.n();
  for (int k = 0; k < n[Z]; ++k)
    for (int j = 0; j < n[Y]; ++j)
      for (int i = 0; i < n[X]; ++i) {
        const double v = f(i, j, k);
        std::uint64_t bits = 0;
        std::memcpy(&bits, &v, sizeof bits);
        for (int b = 0; b < 8; ++b) {
          h ^= (bits >> (8 * b)) & 0xffu;
          h *= 1099511628211ull;
        }
      }
  return h;
}

// The ranks' hashes combined in rank order (every rank gets it).
std::uint64_t global_hash(const Field& f, MPI_Comm comm) {
  const std::uint64_t mine = field_hash(f);
  std::vector<std::uint64_t> all(static_cast<std::size_t>(testing::world_size()));
  MPI_Allgather(&mine, 1, MPI_UINT64_T, all.data(), 1, MPI_UINT64_T, comm);
  std::uint64_t h = 1469598103934665603ull;
  for (std::uint64_t r : all) h = (h ^ r) * 1099511628211ull;
  return h;
}

const char* const kFieldNames[] = {"u", "v", "w", "p", "phi", "B11", "B22", "B33", "B12", "B13", "B23"};

// {"acm/sync u": hash, ...} after kSteps steps of `c`.
std::map<std::string, std::uint64_t> run_case(const Case& c) {
  const int p = testing::world_size();
  ChannelCase cc = weak_block_case(kBlock, p);
  cc.solver.dt = c.dt;
  cc.solver.comm = c.mode;
  OptionValues given;
  if (c.ns > 0) given["--ns"] = c.ns;
  choose_method(cc, configure_method(c.method, given, c.nc));
  cc.timed_planning = false;
  const auto particles = validate_case(cc, p, 1000 * c.dt);
  CartDecomposition dec(MPI_COMM_WORLD, cc.domain.cells, kTransportHalo, cc.forced_dims);
  auto solver = build_solver(cc, dec, particles);
  solver->impose_laminar_flow();
  for (int s = 0; s < kSteps; ++s) solver->step();
  solver->complete_exchange();
  std::map<std::string, std::uint64_t> out;
  const std::vector<Field*> fields = solver->state().all();
  for (std::size_t f = 0; f < fields.size(); ++f)
    out[case_name(c) + " " + kFieldNames[f]] = global_hash(*fields[f], dec.comm());
  return out;
}

const std::vector<Case>& cases() {
  static const std::vector<Case> all{
      {"acm", CommMode::sync, 1.25e-5, 0, 0},   {"acm", CommMode::async, 1.25e-5, 0, 0},
      {"sor", CommMode::sync, 6.25e-5, 64, 20}, {"sor", CommMode::async, 6.25e-5, 64, 20},
      {"fft", CommMode::sync, 6.25e-5, 0, 0},   {"fft", CommMode::async, 6.25e-5, 0, 0},
  };
  return all;
}

std::string data_path() { return std::string(EFSI_TEST_DATA_DIR) + "/step_checksums.txt"; }

std::map<std::string, std::uint64_t> read_reference() {
  std::map<std::string, std::uint64_t> ref;
  std::ifstream in(data_path());
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ls(line);
    std::string name, field, hex;
    ls >> name >> field >> hex;
    ref[name + " " + field] = std::strtoull(hex.c_str(), nullptr, 16);
  }
  return ref;
}

TEST(StepChecksums, EveryFieldOfEveryMethodMatchesTheReference) {
  ASSERT_EQ(testing::world_size(), 2) << "the reference checksums are for 2 ranks";
  std::map<std::string, std::uint64_t> got;
  for (const Case& c : cases()) got.merge(run_case(c));
  if (const char* out = std::getenv("EFSI_WRITE_CHECKSUMS")) {
    if (testing::world_rank() == 0) {
      std::FILE* f = std::fopen(out, "w");
      ASSERT_NE(f, nullptr) << "cannot write " << out;
      std::fprintf(f, "# test_step_checksums: FNV-1a of every state field after %d steps, 2 ranks, %d^3 per rank\n",
                   kSteps, kBlock);
      for (const auto& [key, h] : got) std::fprintf(f, "%s %016" PRIx64 "\n", key.c_str(), h);
      ASSERT_EQ(std::fclose(f), 0) << "cannot write " << out;
    }
    return;
  }
  const auto ref = read_reference();
  ASSERT_EQ(ref.size(), got.size()) << "reference " << data_path() << " has " << ref.size() << " entries";
  for (const auto& [key, h] : got) {
    const auto it = ref.find(key);
    ASSERT_NE(it, ref.end()) << key << " missing from the reference";
    EXPECT_EQ(it->second, h) << key << " differs from the reference";
  }
}

}  // namespace
}  // namespace efsi
