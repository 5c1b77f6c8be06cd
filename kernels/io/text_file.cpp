#include "text_file.hpp"

#include <fcntl.h>
#include <mpi.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "config_error.hpp"

namespace efsi {
namespace {

// Whole files are written beside `path` and renamed onto it (write_whole_file, and HDF5's
// write_hdf5_atomically), and a missing CSV is created there, so a file is actually created
// beside `path` and removed again: access() answers yes to root for /proc, a read-only mount
// or a full inode table, where only a real creation tells.  An existing special file (a
// device, a FIFO) is refused: a temporary beside it would land in /dev, and the suite's
// outputs are meant to be kept.
struct Probe {
  enum Result : int { ok, not_regular, not_writable, no_new_file } result = ok;
  int err = 0;
};

Probe probe(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (!S_ISREG(st.st_mode)) return {Probe::not_regular, 0};
    if (::access(path.c_str(), W_OK) != 0) return {Probe::not_writable, errno};
  } else if (errno != ENOENT) {
    return {Probe::not_writable, errno};
  }
  const std::string probe_file = path + ".probe." + std::to_string(::getpid());
  const int fd = ::open(probe_file.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) return {Probe::no_new_file, errno};
  ::close(fd);
  if (::unlink(probe_file.c_str()) != 0) return {Probe::no_new_file, errno};
  return {};
}

[[noreturn]] void fail(const std::string& path, const std::string& reason) {
  throw std::runtime_error("cannot write " + path + ": " + reason);
}

// 0, or the errno of the first write that failed.
int write_all(int fd, std::string_view data) {
  while (!data.empty()) {
    const ssize_t w = ::write(fd, data.data(), data.size());
    if (w < 0 && errno == EINTR) continue;
    if (w < 0) return errno;
    if (w == 0) return EIO;
    data.remove_prefix(static_cast<std::size_t>(w));
  }
  return 0;
}

// 0, or the errno of fsync: a written byte that the disk then refuses (NFS, a full quota) is
// reported here or at close, not by write().  A special file that cannot sync answers EINVAL.
int sync_file(int fd) { return ::fsync(fd) == 0 || errno == EINVAL ? 0 : errno; }

// Drops what a failed append left; the append's own error is the one to report, so a failure
// here adds nothing.
void cut_back(int fd, off_t size) {
  while (::ftruncate(fd, size) != 0 && errno == EINTR) {
  }
}

}  // namespace

void check_writable(const std::string& path, const char* option) {
  if (path.empty()) return;
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  Probe p;
  if (rank == 0) p = probe(path);
  int state[2] = {p.result, p.err};
  MPI_Bcast(state, 2, MPI_INT, 0, MPI_COMM_WORLD);
  const std::string what = std::string(option) + " '" + path + "'";
  const std::string reason = std::strerror(state[1]);
  switch (state[0]) {
    case Probe::not_regular: throw ConfigError(what + " is not a regular file");
    case Probe::not_writable: throw ConfigError(what + " cannot be written: " + reason);
    case Probe::no_new_file: throw ConfigError(what + " cannot be written: no file can be created beside it (" + reason + ")");
    default: return;
  }
}

void write_whole_file(const std::string& path, const std::vector<std::string_view>& pieces) {
  // The pid keeps concurrent runs writing the same final name apart; the last rename wins.
  const std::string temp = path + ".tmp." + std::to_string(::getpid());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) fail(path, "cannot create " + temp + ": " + std::strerror(errno));
  int err = 0;
  for (std::size_t p = 0; p < pieces.size() && !err; ++p) err = write_all(fd, pieces[p]);
  if (!err) err = sync_file(fd);
  if (::close(fd) != 0 && !err) err = errno;
  if (!err && ::rename(temp.c_str(), path.c_str()) != 0) err = errno;
  if (err) {
    ::unlink(temp.c_str());
    fail(path, std::strerror(err));
  }
}

void append_locked(const std::string& path, const std::string& header, const std::string& rows) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot open " + path + ": " + std::strerror(errno));
  if (::flock(fd, LOCK_EX) != 0) {
    const int e = errno;
    ::close(fd);
    throw std::runtime_error("cannot lock " + path + ": " + std::strerror(e));
  }
  struct stat st {};
  int err = ::fstat(fd, &st) == 0 ? 0 : errno;
  if (!err) err = write_all(fd, st.st_size == 0 ? header + rows : rows);
  if (!err) err = sync_file(fd);
  // Still under the lock: a reader never sees the partial row, and the next writer appends
  // after whole rows only.
  if (err && S_ISREG(st.st_mode)) cut_back(fd, st.st_size);
  if (::close(fd) != 0 && !err) err = errno;  // also releases the lock
  if (err) fail(path, std::strerror(err));
}

void write_on_root(const std::function<void()>& write) {
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  std::string message;
  if (rank == 0) try {
      write();
    } catch (const std::exception& e) {
      message = *e.what() ? e.what() : "an output could not be written";
    }
  agree_on_failure(MPI_COMM_WORLD, message);
}

}  // namespace efsi
