#pragma once
// Parallel HDF5 files (MPI-IO): snapshots and checkpoints.  Each field is one dataset of
// its global points (z slowest, x fastest: N, or N + 1 along y for a field on y faces, both
// walls included), and every rank writes and reads its own owned points as a hyperslab,
// collectively, with no gather.  So the file does not depend on the decomposition that
// wrote it, and any rank count can read it.
//
// Every call is collective over the decomposition's communicator.  A failure on any rank
// (HDF5's own, or the file system's: no space, no permission) becomes the same OutputError on
// every rank, naming the file and the first failing rank's reason, so that no rank goes on
// into a collective call the others have left.
#include <hdf5.h>

#include <functional>
#include <string>
#include <vector>

#include "decomposition.hpp"
#include "field.hpp"
#include "output_error.hpp"

namespace efsi {

class Hdf5File {
 public:
  enum class Mode { create, read };
  // create: a new file (an existing one is replaced); read: an existing file, read only.
  Hdf5File(const std::string& path, Mode mode, const CartDecomposition& decomp);
  ~Hdf5File();  // closes what is still open without reporting: close() is the checked way
  Hdf5File(const Hdf5File&) = delete;
  Hdf5File& operator=(const Hdf5File&) = delete;

  const std::string& path() const { return path_; }

  // The field's owned points as dataset `name` (double, global point shape).
  void write_field(const std::string& name, const Field& f);
  // The owned points of `f` from dataset `name`; ghosts are left as they were.  OutputError
  // when the dataset is absent or its shape is not the field's global one.
  void read_field(const std::string& name, Field& f);

  // Attributes of the root group: the same value on every rank.
  void set_attribute(const std::string& name, const std::string& value);
  void set_attribute(const std::string& name, double value);
  void set_attribute(const std::string& name, long value);
  bool has_attribute(const std::string& name);
  std::string string_attribute(const std::string& name);
  double double_attribute(const std::string& name);
  long long_attribute(const std::string& name);

  // Text of any length (a run's series so far) as a byte dataset, written by rank 0.
  void write_text(const std::string& name, const std::string& text);
  std::string read_text(const std::string& name);

  // Reserves `bytes` of disk for the file (fallocate, keeping its size), so that HDF5's
  // writes cannot run out of room: HDF5 cannot close a file whose writes failed, and crashes
  // in MPI_Finalize over it.  Writing only; collective.
  void reserve(std::size_t bytes);
  // A bound on the file holding these fields' datasets and `text_bytes` of text, with room
  // for the attributes and HDF5's own metadata.
  static std::size_t bytes_needed(const std::vector<const Field*>& fields, const CartDecomposition& decomp,
                                  std::size_t text_bytes = 0);

  // Flushes and closes; OutputError on every rank if any rank's close failed.
  void close();

 private:
  // Throws OutputError on every rank when any rank's `ok` is false (collective).
  void agree(bool ok, const std::string& what);
  void read_attribute(const std::string& name, hid_t mem_type, void* out);
  void write_attribute(const std::string& name, hid_t file_type, hid_t mem_type, const void* value);
  // Closes the file without reporting: the error paths.
  void release();

  std::string path_;
  const CartDecomposition& decomp_;
  hid_t file_ = -1, xfer_ = -1;
  std::size_t reserved_ = 0;
};

// Writes a new HDF5 file under PATH.tmp with `fill`, closes it and, once every rank has
// closed it without error, renames it to `path`: a run stopped or failing while writing
// leaves whatever was under `path` before (the previous checkpoint) intact, and no
// temporary file after an error it reports.  Collective.
// `bytes` bounds the file (bytes_needed): a file system without that room fails before HDF5
// creates anything (see reserve()).
void write_hdf5_atomically(const std::string& path, const CartDecomposition& decomp, std::size_t bytes,
                           const std::function<void(Hdf5File&)>& fill);

}  // namespace efsi
