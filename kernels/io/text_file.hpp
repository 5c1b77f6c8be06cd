#pragma once
// Every text file the suite writes goes through here (docs/architecture.md, "Adding an output
// format"): whole files (series, centroids, profiles, the calibration's history, the
// accuracy comparison) and rows appended under a lock (the CSV run record), each write
// checked, a failure an exception naming the file and the reason.
#include <string>

namespace efsi {

// Collective over MPI_COMM_WORLD: rank 0 checks that `path` can be created or written and
// every rank throws ConfigError ("--series 'PATH' cannot be written") if not; creates
// nothing.  An empty path passes.
void check_writable(const std::string& path, const char* option);

// Writes (truncates) `path` with `text`; throws std::runtime_error naming the file.
void write_text_file(const std::string& path, const std::string& text);

// Appends `rows` to `path` under an exclusive lock (flock), with `header` first when the file
// is new or empty, in one write, so that concurrent writers never interleave or lose a row;
// throws std::runtime_error naming the file and the reason.
void append_locked(const std::string& path, const std::string& header, const std::string& rows);

}  // namespace efsi
