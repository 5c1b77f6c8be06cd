#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, and runs the quick local
# campaign into results/local/ (a few minutes on 2 cores):
#   - weak scaling, the paper's 64^3 block and 2 particles per rank, on 1 and 2 ranks, every
#     method (acm, sor at eps 1e-3 and 1e-4, fft) in both halo modes, 3 measured steps each;
#   - strong scaling of the paper's case divided by 16 per direction, the same sweep;
#   - the accuracy comparison (ACM against the FFT reference) on the 3.6^3 block at 32^3, with
#     HDF5 snapshots of both at t = 0, 0.125 and 0.25;
#   - the paper's figures and tables beside ours, PNG and PDF, in results/local/plots/.
# The full-length campaign committed in results/campaign/ is the same with the paper's step
# counts (see results/README.md).
set -euo pipefail
cd "$(dirname "$0")/.."
bash ci/install-deps.sh
bash ci/build.sh release

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
py=/usr/bin/python3  # Debian's, with matplotlib
out=results/local
rm -rf "$out/weak.csv" "$out/strong.csv" "$out/accuracy" "$out/plots"
mkdir -p "$out/accuracy"
"$py" harness/campaign.py local --sweep quick-weak --csv "$out/weak.csv"
"$py" harness/campaign.py local --sweep quick-strong --csv "$out/strong.csv"
OMP_NUM_THREADS=1 mpirun -n 2 --bind-to core build/bin/accuracy --cells 32 --length 3.6 --t-end 0.25 \
  --snapshot-every 250 --out "$out/accuracy" --csv "$out/accuracy/accuracy.csv"
"$py" plots/make_plots.py --csv "$out/weak.csv" --csv "$out/strong.csv" --accuracy-dir "$out/accuracy" \
  --surface-times 0,0.125,0.25 --out "$out/plots"
echo "wrote $out/weak.csv, $out/strong.csv, $out/accuracy/ and $out/plots/"
