#!/usr/bin/env bash
# The README's test command: installs what is missing, builds, runs every test
# (MPI tests on 1 to 8 ranks and one on 64, oversubscribed on small machines), then, for the release build,
# the micro-benchmark gate (harness/microbench/README.md: bench_kernels on 2 ranks against
# the committed baseline, about half a minute).
#   ci/test.sh            release build
#   ci/test.sh debug      AddressSanitizer + UndefinedBehaviorSanitizer build
set -euo pipefail
cd "$(dirname "$0")/.."
preset="${1:-release}"
bash ci/install-deps.sh
bash ci/build.sh "$preset"
# The simulation build (SimGrid's SMPI, build-simgrid/), which driver_simulation_build runs.
bash ci/build.sh simgrid
ctest --preset "$preset"
if [ "$preset" = release ]; then bash ci/microbench_gate.sh build; fi
