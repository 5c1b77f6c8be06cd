// The io layer's writes (kernels/io/text_file.hpp): a whole file replaces its final name only
// once complete, and a failed append leaves the rows that were there.  The full file system
// is a 64 KiB tmpfs, mounted where that is permitted (root) and skipped otherwise.
#include <gtest/gtest.h>
#include <sys/mount.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>

#include "text_file.hpp"

using namespace efsi;
namespace fs = std::filesystem;

namespace {

std::string read(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

std::set<std::string> names(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

// A fresh directory, removed at the end; `tmpfs` mounts a 64 KiB one on it.
class Scratch : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string tmpl = (fs::temp_directory_path() / "efsi_text_file_XXXXXX").string();
    ASSERT_NE(::mkdtemp(tmpl.data()), nullptr);
    dir_ = tmpl;
  }
  void TearDown() override {
    if (mounted_) ::umount(dir_.c_str());
    fs::remove_all(dir_);
  }
  bool mount_small_tmpfs() {
    mounted_ = ::mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=64k") == 0;
    return mounted_;
  }
  // Takes every free block, so that the next write fails with ENOSPC.
  void fill() {
    std::ofstream f(dir_ / "filler", std::ios::binary);
    const std::string block(4096, '\0');
    while (f.write(block.data(), block.size()) && f.flush()) {
    }
  }
  fs::path dir_;
  bool mounted_ = false;
};

TEST_F(Scratch, WholeFileReplacesAndLeavesNoTemporary) {
  const fs::path p = dir_ / "series.csv";
  write_text_file(p.string(), "old\n");
  write_whole_file(p.string(), {"a,", "b\n", ""});
  EXPECT_EQ(read(p), "a,b\n");
  EXPECT_EQ(names(dir_), std::set<std::string>{"series.csv"});
}

TEST_F(Scratch, FullFileSystemKeepsThePreviousContent) {
  if (!mount_small_tmpfs()) GTEST_SKIP() << "cannot mount a tmpfs (needs root): " << std::strerror(errno);
  const fs::path p = dir_ / "series.csv";
  write_text_file(p.string(), "good\n");
  fill();
  try {
    write_text_file(p.string(), std::string(20000, 'x'));
    FAIL() << "a write to a full file system succeeded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("No space left on device"), std::string::npos) << e.what();
  }
  EXPECT_EQ(read(p), "good\n");
  EXPECT_EQ(names(dir_), (std::set<std::string>{"filler", "series.csv"}));
}

TEST_F(Scratch, FailedAppendLeavesNoPartialRow) {
  if (!mount_small_tmpfs()) GTEST_SKIP() << "cannot mount a tmpfs (needs root): " << std::strerror(errno);
  const fs::path p = dir_ / "run.csv";
  append_locked(p.string(), "h\n", "row\n");
  fill();
  // The file's page still has room: part of the row is written before ENOSPC.
  EXPECT_THROW(append_locked(p.string(), "h\n", std::string(20000, 'r') + "\n"), std::runtime_error);
  EXPECT_EQ(read(p), "h\nrow\n");
}

}  // namespace
