// check_node_memory (memory_estimate.hpp): the per-rank bytes summed over the node's ranks
// against a faked MemAvailable (EFSI_MEMINFO), the same verdict and line on every rank,
// --force-memory, and no refusal where MemAvailable cannot be read. On 1 and 2 ranks: one
// node either way.
#include <gtest/gtest.h>
#include <mpi.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "config_error.hpp"
#include "memory_estimate.hpp"

using namespace efsi;

namespace {

constexpr std::size_t kMiB = 1024 * 1024;

int world_size() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

int world_rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

// Each rank its own file (no rank waits for another's), the node's first rank reads its own.
class NodeMemory : public ::testing::Test {
 protected:
  void SetUp() override { path_ = "/tmp/efsi_test_meminfo_" + std::to_string(getpid()); }
  void TearDown() override {
    std::remove(path_.c_str());
    unsetenv("EFSI_MEMINFO");
  }
  void fake(const std::string& text) {
    std::ofstream(path_) << text;
    setenv("EFSI_MEMINFO", path_.c_str(), 1);
  }
  // The ConfigError's line, or "" when check_node_memory accepted.
  static std::string verdict(std::size_t bytes, bool force = false) {
    try {
      check_node_memory(bytes, force);
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "";
  }
  std::string path_;
};

TEST_F(NodeMemory, RefusesTheNodesSumOverMemAvailable) {
  fake("MemTotal: 4096000 kB\nMemAvailable: 102400 kB\n");  // 100 MiB
  const int n = world_size();
  EXPECT_EQ(verdict(100 * kMiB / n - kMiB), "") << "just under: accepted";
  const std::string line = verdict(100 * kMiB / n + kMiB);
  const std::string per_rank = n == 1 ? "(1 rank x 0.0986 GiB" : "(2 ranks x 0.0498 GiB";
  EXPECT_NE(line.find(per_rank + ", estimated) but 0.0977 GiB are available (MemAvailable)"), std::string::npos)
      << line;
  EXPECT_NE(line.find("on this node"), std::string::npos) << line;
  EXPECT_NE(line.find("; --force-memory runs it anyway"), std::string::npos) << line;
  EXPECT_EQ(line.find('\n'), std::string::npos) << "one line";
}

TEST_F(NodeMemory, RanksOfDifferentSizesAreSummedAndTheLargestNamed) {
  if (world_size() != 2) GTEST_SKIP() << "needs 2 ranks";
  fake("MemAvailable: 102400 kB\n");
  // 10 + 95 MiB: each alone fits, together not; the line names the larger.
  const std::string line = verdict((world_rank() == 0 ? 10 : 95) * kMiB);
  EXPECT_NE(line.find("needs 0.103 GiB on this node (2 ranks, up to 0.0928 GiB each, estimated)"), std::string::npos)
      << line;
}

TEST_F(NodeMemory, ForceRunsAnyway) {
  fake("MemAvailable: 1000 kB\n");
  EXPECT_EQ(verdict(100 * kMiB, true), "");
}

TEST_F(NodeMemory, UnreadableMemAvailableRefusesNothing) {
  fake("MemTotal: 4096000 kB\nMemFree: 1000 kB\n");  // a kernel before 3.14
  EXPECT_EQ(verdict(std::size_t(1) << 50), "");
  setenv("EFSI_MEMINFO", "/nonexistent/meminfo", 1);
  EXPECT_EQ(verdict(std::size_t(1) << 50), "");
}

}  // namespace
