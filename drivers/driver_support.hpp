#pragma once
// What every driver shares: MPI start-up, CLI11 parsing with one-line errors (exit 2),
// "N or NX,NY,NZ" options, and the mapping of failures to exit codes.
#include <CLI/CLI.hpp>

#include <array>
#include <functional>
#include <string>

#include "grid_types.hpp"

namespace efsi {

// "64" -> {64, 64, 64}; "128,64,64" -> as given. Throws ConfigError naming the option.
Int3 parse_int3(const std::string& text, const std::string& option);
std::array<double, 3> parse_double3(const std::string& text, const std::string& option);

// Runs a driver: starts MPI; parses `app` (--help prints and exits 0; a bad option prints
// one line and exits 2, on rank 0 only); then runs `body`, whose own status is 0 for a valid
// run and 4 for one that failed its validation. ConfigError -> one line, exit 2; BlowUp ->
// one line, exit 3; OutputError (an output not written after the run, every rank alike) ->
// one line, exit 5; anything else -> one line per failing rank and MPI_Abort, exit 1.
int run_driver(int argc, char** argv, CLI::App& app, const std::function<int()>& body);

// --force-memory, for every driver that allocates a case (check_node_memory).
void add_force_memory_flag(CLI::App& app, bool& force_memory);

// Rank 0 of MPI_COMM_WORLD.
bool is_root();

}  // namespace efsi
