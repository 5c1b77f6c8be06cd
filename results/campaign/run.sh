#!/usr/bin/env bash
# The campaign whose results lie beside this file: the paper's step counts on this machine
# (2 cores), weak and strong scaling on 1 and 2 ranks for every method and mode, repeated
# (medians in the plots), the accuracy comparison at 64^3, and the plots. Run from the
# repository root after `bash ci/build.sh release`, on an otherwise idle machine.
set -euo pipefail
cd "$(dirname "$0")/../.."
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
py=/usr/bin/python3
out=results/campaign
# The drivers append their rows: a retake starts from empty files, not on top of the last take.
rm -f "$out/weak.csv" "$out/strong.csv" "$out/accuracy/accuracy.csv"
"$py" harness/campaign.py local --sweep local-weak --repeats 3 --csv "$out/weak.csv"
"$py" harness/campaign.py local --sweep local-strong --repeats 2 --csv "$out/strong.csv"
OMP_NUM_THREADS=1 mpirun -n 2 --bind-to core build/bin/accuracy --cells 64 --t-end 4 --every 20 \
  --out "$out/accuracy" --csv "$out/accuracy/accuracy.csv" > "$out/accuracy/accuracy.log"
"$py" plots/make_plots.py --csv "$out/weak.csv" --csv "$out/strong.csv" --accuracy-dir "$out/accuracy" \
  --out "$out/plots"
