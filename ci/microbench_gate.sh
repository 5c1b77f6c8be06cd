#!/usr/bin/env bash
# CI micro-benchmark gate (harness/microbench/README.md).  Decides on counted work, which does
# not depend on the host or its load: bench_kernels, built for a fixed target (the `counted`
# preset, -march=x86-64-v3, which Valgrind executes), runs once on 2 MPI ranks under
# callgrind with simulated caches; per kernel its instructions, estimated cycles and MPI
# messages and bytes are compared with the committed baseline of that build configuration
# (results/microbench/baseline/counts-<configuration>.json).  A short timed run of the
# native build is printed beside, as information.
#   ci/microbench_gate.sh [BUILD_DIR]                      the gate (timed build: build/)
#   ci/microbench_gate.sh --refresh-baseline [BUILD_DIR]   rewrites the baseline from one
#                                                          counted run (counts repeat exactly)
# Environment: EFSI_GATE_OUT (default results/local/microbench-gate), EFSI_GATE_MACHINE
# (recorded in a refreshed baseline, default dev-2core), EFSI_GATE_TIMED=0 (skip the timed run).
set -euo pipefail
cd "$(dirname "$0")/.."
refresh=0
if [ "${1:-}" = "--refresh-baseline" ]; then refresh=1; shift; fi
build="${1:-build}"
out="${EFSI_GATE_OUT:-results/local/microbench-gate}"
counted_build=build-counted
py=/usr/bin/python3
command -v valgrind >/dev/null || { echo "microbench gate: valgrind not found (Debian package valgrind; ci/install-deps.sh installs it)"; exit 1; }

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMP_NUM_THREADS=1
# Single-copy (CMA) transfers need ptrace rights between the ranks, which containers often deny.
export OMPI_MCA_btl_vader_single_copy_mechanism=none
# The counted set: every kernel at 32^3 per rank, whole steps at 32^3, the global reduction.
filter='/32/|^BM_GlobalReduction'

start=$SECONDS
mkdir -p "$out"
cmake --preset counted >/dev/null
cmake --build --preset counted >"$out/counted-build.log" 2>&1 ||
  { tail -n 30 "$out/counted-build.log"; echo "microbench gate: the counted build failed"; exit 1; }

# Instrumentation and collection start off; bench_kernels switches them on around each kernel
# (callgrind_region.hpp).  Caches fixed to this machine kind's per-core L1 and L2 (Zen 4:
# 32 KiB 8-way each, 1 MiB 8-way), not taken from the host's CPUID.
rm -rf "$out/counted"
mkdir -p "$out/counted"
if ! EFSI_COUNT=1 mpiexec -n 2 --oversubscribe --bind-to none \
    valgrind --tool=callgrind --instr-atstart=no --collect-atstart=no --cache-sim=yes \
      --I1=32768,8,64 --D1=32768,8,64 --LL=1048576,8,64 \
      --callgrind-out-file="$out/counted/cg.%q{OMPI_COMM_WORLD_RANK}" \
      "$counted_build/bin/bench_kernels" --benchmark_filter="$filter" \
      --benchmark_out="$out/counted/counts.json" --benchmark_out_format=json >"$out/counted/log" 2>&1; then
  tail -n 40 "$out/counted/log"
  echo "microbench gate: the counted run failed (log: $out/counted/log)"
  exit 1
fi
echo "counted run: $((SECONDS - start)) s (build and callgrind)"

if [ "$refresh" = 1 ]; then
  exec "$py" harness/microbench/gate.py write "$out/counted" --machine "${EFSI_GATE_MACHINE:-dev-2core}"
fi

timed=()
if [ "${EFSI_GATE_TIMED:-1}" != 0 ] && [ -x "$build/bin/bench_kernels" ]; then
  bind=(--bind-to core)
  [ "$(nproc)" -ge 2 ] || bind=(--oversubscribe --bind-to none)
  if mpiexec -n 2 "${bind[@]}" "$build/bin/bench_kernels" --benchmark_filter='^BM_[A-Za-z]+(/(sync|async))?/(32|64)/|^BM_Step/.*/32/|^BM_GlobalReduction' \
      --benchmark_min_time=0.05 --benchmark_repetitions=3 \
      --benchmark_out="$out/timed.json" --benchmark_out_format=json >"$out/timed.log" 2>&1; then
    timed=(--timed "$out/timed.json")
  else
    echo "microbench gate: the timed run failed (information only; log: $out/timed.log)"
  fi
fi
status=0
"$py" harness/microbench/gate.py check "$out/counted" "${timed[@]}" || status=$?
echo "microbench gate: $((SECONDS - start)) s"
exit $status
