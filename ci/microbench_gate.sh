#!/usr/bin/env bash
# CI micro-benchmark gate (harness/microbench/README.md): runs bench_kernels briefly on 2 MPI
# ranks (every kernel at 32^3 and 64^3 cells per rank, whole steps at 32^3), then compares
# each kernel's ratio (fastest time / the in-run STREAM-triad probe's fastest pass) with the
# committed baseline; fails when one is more than 1.5 times its baseline.
#   ci/microbench_gate.sh [BUILD_DIR]                       the gate (default build/)
#   ci/microbench_gate.sh --refresh-baseline [BUILD_DIR]    rewrites the baseline from the
#                                                           median of 3 runs of the same set
# Environment: EFSI_GATE_BASELINE (default results/microbench/baseline/bench_kernels-2ranks.json),
# EFSI_GATE_OUT (default results/local/microbench-gate.json), EFSI_GATE_FACTOR (1.5),
# EFSI_GATE_MACHINE (name written into a refreshed baseline, default dev-2core).
set -euo pipefail
cd "$(dirname "$0")/.."
refresh=0
if [ "${1:-}" = "--refresh-baseline" ]; then refresh=1; shift; fi
build="${1:-build}"
baseline="${EFSI_GATE_BASELINE:-results/microbench/baseline/bench_kernels-2ranks.json}"
out="${EFSI_GATE_OUT:-results/local/microbench-gate.json}"
factor="${EFSI_GATE_FACTOR:-1.5}"
mkdir -p "$(dirname "$out")"

# The gate's benchmark set; the baseline is written from runs of the same set.
filter='^BM_[A-Za-z]+(/(sync|async))?/(32|64)/|^BM_Step/.*/32/|^BM_GlobalReduction'

run_set() {  # $1: JSON output, $2: filter
  local bind=(--bind-to core) log="${1%.json}.log"
  [ "$(nproc)" -ge 2 ] || bind=(--oversubscribe --bind-to none)
  # EFSI_MPI_WAIT_CLOCK=1: count the CPU time inside MPI's waits (the gate's figure excludes it).
  if ! OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none \
    OMP_NUM_THREADS=1 EFSI_MPI_WAIT_CLOCK=1 mpiexec -n 2 "${bind[@]}" "$build/bin/bench_kernels" \
      --benchmark_filter="$2" --benchmark_min_time=0.1 --benchmark_repetitions=3 \
      --benchmark_out="$1" --benchmark_out_format=json >"$log" 2>&1; then
    tail -n 40 "$log"
    echo "bench_kernels failed (log: $log)"
    exit 1
  fi
}

if [ "$refresh" = 1 ]; then
  runs=()
  for r in 1 2 3; do
    run_set "${out%.json}-refresh$r.json" "$filter"
    runs+=("${out%.json}-refresh$r.json")
  done
  /usr/bin/python3 harness/microbench/gate.py "${runs[@]}" --write-baseline "$baseline" \
    --machine "${EFSI_GATE_MACHINE:-dev-2core}" --command "ci/microbench_gate.sh --refresh-baseline"
  exit 0
fi

# A kernel over the limit is run again (at most twice) before the gate fails: its ratio is
# the least of its runs', so a slowdown must show every time, not once on a busy machine.
runs=("$out")
failed="${out%.json}-failed.txt"
run_set "$out" "$filter"
for attempt in 1 2; do
  if /usr/bin/python3 harness/microbench/gate.py "${runs[@]}" --baseline "$baseline" --factor "$factor" \
    --failed-list "$failed"; then
    exit 0
  fi
  names="$(paste -sd'|' "$failed")"
  echo "rerunning: $names"
  run_set "${out%.json}-rerun$attempt.json" "^($names)/manual_time\$"
  runs+=("${out%.json}-rerun$attempt.json")
done
/usr/bin/python3 harness/microbench/gate.py "${runs[@]}" --baseline "$baseline" --factor "$factor"
