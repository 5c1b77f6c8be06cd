#include "hdf5_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

namespace efsi {
namespace {

// HDF5 prints its error stack to stderr by default, one stack per rank: the suite reports
// one line instead, from the innermost entry (the file system's own message where there is one).
herr_t innermost(unsigned n, const H5E_error2_t* e, void* out) {
  auto* reason = static_cast<std::string*>(out);
  if (n == 0 && e->desc) {
    const std::string desc = e->desc;
    const auto at = desc.find("error message = '");
    if (at != std::string::npos) {
      const auto from = at + std::strlen("error message = '");
      *reason = desc.substr(from, desc.find('\'', from) - from);
    } else {
      *reason = desc;
    }
  }
  return 0;
}

std::string hdf5_reason(const std::string& call) {
  std::string reason;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_UPWARD, innermost, &reason);
  H5Eclear2(H5E_DEFAULT);
  return reason.empty() ? call + " failed" : call + ": " + reason;
}

void quiet_hdf5() {
  static const bool once = [] { return H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr) >= 0; }();
  (void)once;
}

// The field's global point counts, z slowest (HDF5's order is C's: x fastest last).
std::array<hsize_t, 3> global_shape(const Field& f, const CartDecomposition& d) {
  const Int3 g = d.global();
  std::array<hsize_t, 3> s{};
  for (int a = 0; a < 3; ++a) s[2 - a] = hsize_t(g[a] + (a == Y && is_staggered(f.stagger(), Y) ? 1 : 0));
  return s;
}

// The owned points as a hyperslab of the file's global array, and the same points as a
// hyperslab of the field's padded allocation (no copy).
struct Selection {
  hid_t file_space = -1, mem_space = -1;
  ~Selection() {
    if (mem_space >= 0) H5Sclose(mem_space);
    if (file_space >= 0) H5Sclose(file_space);
  }
};

bool select_owned(const Field& f, const CartDecomposition& d, Selection& s) {
  const std::array<hsize_t, 3> shape = global_shape(f, d);
  std::array<hsize_t, 3> start{}, count{};
  for (int a = 0; a < 3; ++a) {
    start[2 - a] = hsize_t(f.offset()[a]);
    count[2 - a] = hsize_t(f.owned_end(a));
  }
  const hsize_t sy = hsize_t(f.stride_y()), sz = hsize_t(f.stride_z());
  const std::array<hsize_t, 3> alloc{hsize_t(f.allocated()) / sz, sz / sy, sy};
  const hsize_t origin = hsize_t(f.index(0, 0, 0));
  const std::array<hsize_t, 3> first{origin / sz, (origin % sz) / sy, origin % sy};
  s.file_space = H5Screate_simple(3, shape.data(), nullptr);
  s.mem_space = H5Screate_simple(3, alloc.data(), nullptr);
  return s.file_space >= 0 && s.mem_space >= 0 &&
         H5Sselect_hyperslab(s.file_space, H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr) >= 0 &&
         H5Sselect_hyperslab(s.mem_space, H5S_SELECT_SET, first.data(), nullptr, count.data(), nullptr) >= 0;
}

// errno of reserving `bytes` for `path` (0 on success, and where the file system cannot
// reserve: EOPNOTSUPP, some network ones); `mode` as fallocate's.
int reserve_on_disk(const std::string& path, std::size_t bytes, int mode) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT, 0644);
  const int err = fd < 0 ? errno : ::fallocate(fd, mode, 0, off_t(bytes)) == 0 ? 0 : errno;
  if (fd >= 0) ::close(fd);
  return err == EOPNOTSUPP || err == ENOSYS ? 0 : err;
}

}  // namespace

Hdf5File::Hdf5File(const std::string& path, Mode mode, const CartDecomposition& decomp)
    : path_(path), decomp_(decomp) {
  quiet_hdf5();
  std::string failure;
  const hid_t access = H5Pcreate(H5P_FILE_ACCESS);
  if (access < 0 || H5Pset_fapl_mpio(access, decomp_.comm(), MPI_INFO_NULL) < 0 ||
      H5Pset_all_coll_metadata_ops(access, true) < 0 || H5Pset_coll_metadata_write(access, true) < 0) {
    failure = hdf5_reason("file access list");
  } else {
    file_ = mode == Mode::create ? H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access)
                                 : H5Fopen(path.c_str(), H5F_ACC_RDONLY, access);
    if (file_ < 0) failure = hdf5_reason(mode == Mode::create ? "create" : "open");
  }
  if (access >= 0) H5Pclose(access);
  xfer_ = H5Pcreate(H5P_DATASET_XFER);
  if (failure.empty() && (xfer_ < 0 || H5Pset_dxpl_mpio(xfer_, H5FD_MPIO_COLLECTIVE) < 0))
    failure = hdf5_reason("transfer list");
  if (!failure.empty()) {  // a constructor that throws runs no destructor
    if (xfer_ >= 0) H5Pclose(xfer_);
    release();
  }
  agree(failure.empty(), failure);
}

Hdf5File::~Hdf5File() {
  if (xfer_ >= 0) H5Pclose(xfer_);
  release();
}

void Hdf5File::release() {
  if (file_ >= 0) H5Fclose(file_);
  H5Eclear2(H5E_DEFAULT);
  file_ = -1;
}

std::size_t Hdf5File::bytes_needed(const std::vector<const Field*>& fields, const CartDecomposition& decomp,
                                   std::size_t text_bytes) {
  constexpr std::size_t kMetadata = 256 * 1024;  // measured: under 10 KiB for a checkpoint
  std::size_t bytes = kMetadata + text_bytes;
  for (const Field* f : fields) {
    const std::array<hsize_t, 3> s = global_shape(*f, decomp);
    bytes += std::size_t(s[0] * s[1] * s[2]) * sizeof(double);
  }
  return bytes;
}

void Hdf5File::reserve(std::size_t bytes) {
  int rank = 0;
  MPI_Comm_rank(decomp_.comm(), &rank);
  std::string failure;
  if (rank == 0) {
    const int err = reserve_on_disk(path_, bytes, FALLOC_FL_KEEP_SIZE);
    if (err != 0)
      failure = std::string(std::strerror(err)) + " (reserving " + std::to_string(bytes) + " bytes for it)";
  }
  agree(failure.empty(), failure);
  reserved_ = bytes;
}

void Hdf5File::agree(bool ok, const std::string& what) {
  agree_on_failure(decomp_.comm(), ok ? std::string() : path_ + ": " + what);
}

void Hdf5File::write_field(const std::string& name, const Field& f) {
  Selection s;
  std::string failure;
  hid_t set = -1;
  if (!select_owned(f, decomp_, s)) {
    failure = hdf5_reason("select " + name);
  } else {
    set = H5Dcreate2(file_, name.c_str(), H5T_IEEE_F64LE, s.file_space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    if (set < 0) failure = hdf5_reason("create dataset " + name);
    else if (H5Dwrite(set, H5T_NATIVE_DOUBLE, s.mem_space, s.file_space, xfer_, f.data()) < 0)
      failure = hdf5_reason("write " + name);
    if (set >= 0 && H5Dclose(set) < 0 && failure.empty()) failure = hdf5_reason("close " + name);
  }
  agree(failure.empty(), failure);
}

void Hdf5File::read_field(const std::string& name, Field& f) {
  Selection s;
  std::string failure;
  const hid_t set = H5Dopen2(file_, name.c_str(), H5P_DEFAULT);
  if (set < 0) {
    failure = "no dataset '" + name + "'";
    H5Eclear2(H5E_DEFAULT);
  } else {
    const hid_t space = H5Dget_space(set);
    std::array<hsize_t, 3> have{};
    const std::array<hsize_t, 3> want = global_shape(f, decomp_);
    if (H5Sget_simple_extent_ndims(space) != 3 || H5Sget_simple_extent_dims(space, have.data(), nullptr) != 3 ||
        have != want) {
      failure = "dataset '" + name + "' is " + std::to_string(have[2]) + "x" + std::to_string(have[1]) + "x" +
                std::to_string(have[0]) + " points, this run's is " + std::to_string(want[2]) + "x" +
                std::to_string(want[1]) + "x" + std::to_string(want[0]);
    } else if (!select_owned(f, decomp_, s)) {
      failure = hdf5_reason("select " + name);
    } else if (H5Dread(set, H5T_NATIVE_DOUBLE, s.mem_space, s.file_space, xfer_, f.data()) < 0) {
      failure = hdf5_reason("read " + name);
    }
    if (space >= 0) H5Sclose(space);
    H5Dclose(set);
  }
  agree(failure.empty(), failure);
}

void Hdf5File::write_attribute(const std::string& name, hid_t file_type, hid_t mem_type, const void* value) {
  const hid_t space = H5Screate(H5S_SCALAR);
  const hid_t attr = H5Acreate2(file_, name.c_str(), file_type, space, H5P_DEFAULT, H5P_DEFAULT);
  const bool ok = attr >= 0 && H5Awrite(attr, mem_type, value) >= 0;
  const std::string failure = ok ? std::string() : hdf5_reason("attribute " + name);
  if (attr >= 0) H5Aclose(attr);
  H5Sclose(space);
  agree(ok, failure);
}

void Hdf5File::set_attribute(const std::string& name, const std::string& value) {
  const hid_t type = H5Tcopy(H5T_C_S1);
  H5Tset_size(type, std::max<std::size_t>(value.size(), 1));
  try {
    write_attribute(name, type, type, value.empty() ? "" : value.c_str());
  } catch (...) {
    H5Tclose(type);
    throw;
  }
  H5Tclose(type);
}

void Hdf5File::set_attribute(const std::string& name, double value) {
  write_attribute(name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, &value);
}

void Hdf5File::set_attribute(const std::string& name, long value) {
  write_attribute(name, H5T_STD_I64LE, H5T_NATIVE_LONG, &value);
}

bool Hdf5File::has_attribute(const std::string& name) {
  const htri_t e = H5Aexists(file_, name.c_str());
  agree(e >= 0, hdf5_reason("attribute " + name));
  return e > 0;
}

void Hdf5File::read_attribute(const std::string& name, hid_t mem_type, void* out) {
  const hid_t attr = H5Aopen(file_, name.c_str(), H5P_DEFAULT);
  const bool ok = attr >= 0 && H5Aread(attr, mem_type, out) >= 0;
  if (!ok) H5Eclear2(H5E_DEFAULT);
  if (attr >= 0) H5Aclose(attr);
  agree(ok, "no readable attribute '" + name + "'");
}

std::string Hdf5File::string_attribute(const std::string& name) {
  const hid_t attr = H5Aopen(file_, name.c_str(), H5P_DEFAULT);
  std::string value;
  bool ok = attr >= 0;
  if (ok) {
    const hid_t type = H5Aget_type(attr);
    ok = type >= 0 && H5Tget_class(type) == H5T_STRING && !H5Tis_variable_str(type);
    if (ok) {
      std::vector<char> b(H5Tget_size(type) + 1, '\0');
      const hid_t mem = H5Tcopy(type);
      ok = H5Aread(attr, mem, b.data()) >= 0;
      H5Tclose(mem);
      value = b.data();
    }
    if (type >= 0) H5Tclose(type);
    H5Aclose(attr);
  }
  if (!ok) H5Eclear2(H5E_DEFAULT);
  agree(ok, "no readable text attribute '" + name + "'");
  return value;
}

double Hdf5File::double_attribute(const std::string& name) {
  double v = 0;
  read_attribute(name, H5T_NATIVE_DOUBLE, &v);
  return v;
}

long Hdf5File::long_attribute(const std::string& name) {
  long v = 0;
  read_attribute(name, H5T_NATIVE_LONG, &v);
  return v;
}

void Hdf5File::write_text(const std::string& name, const std::string& text) {
  const hsize_t n = text.size();
  const hid_t file_space = H5Screate_simple(1, &n, nullptr);
  std::string failure;
  const hid_t set = H5Dcreate2(file_, name.c_str(), H5T_STD_U8LE, file_space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (set < 0) {
    failure = hdf5_reason("create dataset " + name);
  } else {
    int rank = 0;
    MPI_Comm_rank(decomp_.comm(), &rank);
    const hsize_t mine = rank == 0 ? n : 0;
    const hid_t mem_space = H5Screate_simple(1, &mine, nullptr);
    if (rank != 0) {
      H5Sselect_none(file_space);
      H5Sselect_none(mem_space);
    }
    if (n > 0 && H5Dwrite(set, H5T_NATIVE_UCHAR, mem_space, file_space, xfer_, text.data()) < 0)
      failure = hdf5_reason("write " + name);
    H5Sclose(mem_space);
    if (H5Dclose(set) < 0 && failure.empty()) failure = hdf5_reason("close " + name);
  }
  H5Sclose(file_space);
  agree(failure.empty(), failure);
}

std::string Hdf5File::read_text(const std::string& name) {
  std::string text, failure;
  const hid_t set = H5Dopen2(file_, name.c_str(), H5P_DEFAULT);
  if (set < 0) {
    H5Eclear2(H5E_DEFAULT);
    failure = "no dataset '" + name + "'";
  } else {
    const hid_t space = H5Dget_space(set);
    const hssize_t n = H5Sget_simple_extent_npoints(space);
    text.assign(n > 0 ? std::size_t(n) : 0, '\0');
    if (n > 0 && H5Dread(set, H5T_NATIVE_UCHAR, H5S_ALL, H5S_ALL, xfer_, text.data()) < 0)
      failure = hdf5_reason("read " + name);
    H5Sclose(space);
    H5Dclose(set);
  }
  agree(failure.empty(), failure);
  return text;
}

void Hdf5File::close() {
  std::string failure;
  if (xfer_ >= 0) H5Pclose(xfer_);
  xfer_ = -1;
  if (file_ >= 0 && H5Fclose(file_) < 0) {
    failure = hdf5_reason("close");
    release();
  }
  file_ = -1;
  int rank = 0;
  MPI_Comm_rank(decomp_.comm(), &rank);
  // Gives back what the reservation holds beyond the file's end.
  struct stat st {};
  if (failure.empty() && reserved_ > 0 && rank == 0 && ::stat(path_.c_str(), &st) == 0)
    (void)::truncate(path_.c_str(), st.st_size);
  agree(failure.empty(), failure);
}

void write_hdf5_atomically(const std::string& path, const CartDecomposition& decomp, std::size_t bytes,
                           const std::function<void(Hdf5File&)>& fill) {
  const std::string temporary = path + ".tmp";
  int rank = 0;
  MPI_Comm_rank(decomp.comm(), &rank);
  // Room first, before HDF5 holds the file: even the superblock HDF5 writes when it closes
  // an empty file fails on a full disk, and then it crashes in MPI_Finalize.  Creating the
  // file truncates it, so the reservation is made again once HDF5 has created it.
  std::string room;
  if (rank == 0) {
    std::remove(temporary.c_str());  // a killed run's, whose blocks would count as room
    const int err = reserve_on_disk(temporary, bytes, 0);
    std::remove(temporary.c_str());
    if (err != 0)
      room = "cannot write " + path + ": " + std::strerror(err) + " (it needs " + std::to_string(bytes) + " bytes)";
  }
  agree_on_failure(decomp.comm(), room);
  try {
    Hdf5File file(temporary, Hdf5File::Mode::create, decomp);
    file.reserve(bytes);
    fill(file);
    file.close();
  } catch (const OutputError& e) {
    if (rank == 0) std::remove(temporary.c_str());
    std::string reason = e.what();
    if (reason.starts_with(temporary + ": ")) reason.erase(0, temporary.size() + 2);
    throw OutputError("cannot write " + path + ": " + reason);
  }
  std::string failure;
  if (rank == 0 && std::rename(temporary.c_str(), path.c_str()) != 0) {
    failure = "cannot rename " + temporary + " to " + path + ": " + std::strerror(errno);
    std::remove(temporary.c_str());
  }
  agree_on_failure(decomp.comm(), failure);
}

}  // namespace efsi
