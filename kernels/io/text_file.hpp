#pragma once
// Every file the suite writes goes through here (docs/architecture.md, "Adding an output
// format"): whole files (series, centroids, profiles, the calibration's history, the
// accuracy comparison, VTK images) replace their final name only once complete, and rows
// appended under a lock (the CSV run record); each write checked, a failure an exception
// naming the file and the reason.
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "output_error.hpp"

namespace efsi {

// Collective over MPI_COMM_WORLD, before a run: rank 0 creates and removes a file beside
// `path` (where its temporary or, for a CSV, the file itself will be created) and checks that
// an existing `path` is a regular file it may write; every rank throws ConfigError
// ("--series 'PATH' cannot be written: REASON", "... is not a regular file") if not.  Leaves
// nothing behind.  An empty path passes.
void check_writable(const std::string& path, const char* option);

// `pieces`, one after another, become the whole of `path`: written to a temporary beside it,
// synced, then renamed onto it, so that `path` holds either its old content or all of the new
// one, never part of it.  Throws std::runtime_error naming the file and the reason, after
// removing the temporary.
void write_whole_file(const std::string& path, const std::vector<std::string_view>& pieces);

inline void write_text_file(const std::string& path, std::string_view text) { write_whole_file(path, {text}); }

// Appends `rows` to `path` under an exclusive lock (flock), with `header` first when the file
// is new or empty, in one write, so that concurrent writers never interleave or lose a row;
// a failed append is cut off again, so that no partial row stays.  Throws std::runtime_error
// naming the file and the reason.
void append_locked(const std::string& path, const std::string& header, const std::string& rows);

// Collective over MPI_COMM_WORLD: runs `write` on rank 0; when it throws, every rank throws
// OutputError with rank 0's message, so that a failed output ends every rank alike.
void write_on_root(const std::function<void()>& write);

}  // namespace efsi
