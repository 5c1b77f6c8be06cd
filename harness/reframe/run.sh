#!/usr/bin/env bash
# Runs the EFSI-Bench ReFrame checks on one partition of a configured system.
#   harness/reframe/run.sh local|slurm [REFRAME OPTIONS...]    (dev-2core, this machine)
#   EFSI_REFRAME_CONFIG=FILE EFSI_REFRAME_SYSTEM=SYS harness/reframe/run.sh PART [...]
# The slurm partition needs the local cluster running and its SLURM_CONF exported
# (harness/slurm-local/local_cluster.py start).  Stage, output, perflogs, reframe.log and the
# JSON report go to $EFSI_REFRAME_OUT (default results/local/reframe); the drivers come from
# $EFSI_BIN_DIR (default build/bin).  Extra options go to reframe, e.g. -n weak_scaling-acm,
# --skip-performance-check, -S ranks=1 -S threads=2.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
part="${1:-}"
if [ -z "$part" ] || [[ "$part" == -* ]]; then
  echo "run.sh: error: give the partition first (local or slurm), not '${part}'" >&2
  exit 2
fi
shift
config="${EFSI_REFRAME_CONFIG:-$here/config/dev_2core.py}"
system="${EFSI_REFRAME_SYSTEM:-dev-2core}"
out="$(mkdir -p "${EFSI_REFRAME_OUT:-$repo/results/local/reframe}" && cd "${EFSI_REFRAME_OUT:-$repo/results/local/reframe}" && pwd)"
if [ "$part" = slurm ] && [ -z "${SLURM_CONF:-}" ] && [ "$system" = dev-2core ]; then
  echo "run.sh: error: SLURM_CONF is not set: start harness/slurm-local/local_cluster.py and export it" >&2
  exit 2
fi
bash "$here/setup-venv.sh"
export EFSI_BIN_DIR="${EFSI_BIN_DIR:-$repo/build/bin}"
# Open MPI refuses root unless told; the checks do not care who runs them.
if [ "$(id -u)" -eq 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
cd "$out"
exec "$here/.venv/bin/reframe" -C "$config" --system "$system:$part" -c "$here/checks/efsi_drivers.py" \
  --prefix "$out" --report-file "$out/report-$part.json" -r "$@"
