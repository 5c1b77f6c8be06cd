#!/usr/bin/env bash
# Runs a driver of the simulation build (build-simgrid/, the `simgrid` preset) as N simulated
# ranks under smpirun on a platform file, ranks filled node by node, PER_NODE on each (more
# than a node's cores share them, as oversubscribed ranks do).
#   harness/simgrid/run.sh PLATFORM.xml N PER_NODE DRIVER [driver options...]
# e.g. harness/simgrid/run.sh harness/simgrid/platforms/dev-2core.xml 2 2 \
#        build-simgrid/bin/weak_scaling --local 32 --steps 3 --csv sim.csv
# The nodes are the platform's hosts node-0, node-1, ...  Environment: EFSI_SMPI_CFG, more
# --cfg=... options for smpirun.
set -euo pipefail
if [ $# -lt 4 ]; then
  echo "usage: $0 PLATFORM.xml RANKS RANKS_PER_NODE DRIVER [options...]" >&2
  exit 2
fi
platform=$1 ranks=$2 per_node=$3
shift 3
[ -f "$platform" ] || { echo "run.sh: platform '$platform' not found" >&2; exit 2; }
[[ "$ranks" =~ ^[1-9][0-9]*$ ]] || { echo "run.sh: rank count '$ranks' is not a positive integer" >&2; exit 2; }
[[ "$per_node" =~ ^[1-9][0-9]*$ ]] || { echo "run.sh: ranks per node '$per_node' is not a positive integer" >&2; exit 2; }
hosts=$(mktemp)
trap 'rm -f "$hosts"' EXIT
nodes=$(( (ranks + per_node - 1) / per_node ))
for ((n = 0; n < nodes; ++n)); do echo "node-$n:$per_node"; done > "$hosts"
# Compute is charged by the stages themselves (kernels/grid/compute_model.hpp), so SMPI's
# own benchmarking of the code between MPI calls is off; the simulated ranks' arrays are
# folded onto shared pages (global: one block mapped again and again, which needs
# vm.max_map_count above the blocks mapped); the Open MPI selector picks the collective
# algorithms Open MPI 4.1's fixed rules pick (a small allreduce: recursive doubling below
# 256 ranks, a reduce and a broadcast from 256 on), but for the broadcast of small messages
# at 256 ranks and more: there Open MPI takes a k-nomial tree (radix 4), which SMPI stands
# in for with MVAPICH2's intra-node k-nomial, whose requests cost the simulator minutes per
# call from 1024 ranks (30 s for one 8-byte allreduce at 1024 ranks against 0.6 s with a
# binomial tree).  A binomial tree takes log2 P rounds where the k-nomial takes 1.5 log2 P
# sends in log4 P rounds: microseconds a step, where a step takes a fraction of a second.
# SMPI's default charges 100 us for each MPI_Test that finds a message still flying, and
# more for each one after it (smpi/test, smpi/grow-injected-times): a knob to make polling
# programs simulate faster, not a model of Open MPI, whose test takes well under a
# microsecond; with it, the async SOR's tests added 0.4 s a step at 8 ranks, all counted
# as communication.
exec smpirun -np "$ranks" -platform "$platform" -hostfile "$hosts" \
  --cfg=smpi/simulate-computation:no --cfg=smpi/shared-malloc:global \
  --cfg=smpi/coll-selector:ompi --cfg=smpi/bcast:binomial_tree --cfg=smpi/test:0 --log=root.thres:warning \
  ${EFSI_SMPI_CFG:-} "$@"
