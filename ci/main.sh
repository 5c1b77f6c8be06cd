#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the main job.
# For now the main job is a short channel run of the paper's weak-scaling block on 2 ranks
# (64^3 cells and 2 particles per rank, ACM, sync and async), appending CSV rows and diagnostic
# series to results/local/, then the batched halo-exchange benchmark (Google Benchmark JSON).
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
bash ci/build.sh release

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-1}"
out=results/local
mkdir -p "$out"
ranks=2
cores=$(nproc)
extra=()
if [ "$ranks" -gt "$cores" ]; then
  echo "warning: $ranks ranks on $cores cores: oversubscribed, timings not representative" >&2
  extra+=(--oversubscribe)
fi
for comm in sync async; do
  mpirun -n "$ranks" "${extra[@]}" build/bin/channel --cells 128,64,64 --length 7.2,3.6,3.6 \
    --steps 20 --comm "$comm" --csv "$out/channel.csv" --series "$out/series-$comm.csv" --every 5
done
mpirun -n "$ranks" "${extra[@]}" build/bin/bench_halo_exchange \
  --benchmark_min_time=0.5 --benchmark_repetitions=3 --benchmark_report_aggregates_only=true \
  --benchmark_out="$out/bench_halo_exchange.json" --benchmark_out_format=json
echo "wrote $out/channel.csv, $out/series-{sync,async}.csv, $out/bench_halo_exchange.json"
