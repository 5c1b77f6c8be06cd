#!/usr/bin/env bash
# The committed predictions of results/simulated/ (harness/simgrid/README.md): the paper's
# weak-scaling block (64^3 cells, 2 particles a rank) with ACM, simulated on the RICC
# platform with its calibrated efficiencies, 8 ranks a node.  Simulated time has no noise, so
# a few steps give the per-step time of the paper's 50.
#   results/simulated/run.sh [RANKS ...]      default: 1 8 64 512
# Needs the simulation build (cmake --preset simgrid && cmake --build --preset simgrid) and,
# from 512 ranks, vm.max_map_count raised (sysctl -w vm.max_map_count=4194304).
set -euo pipefail
cd "$(dirname "$0")/../.."
out=results/simulated/ricc-weak-acm.csv
ranks=("$@")
[ ${#ranks[@]} -gt 0 ] || ranks=(1 8 64 512)
rm -f "$out"
for n in "${ranks[@]}"; do
  steps=5
  [ "$n" -ge 512 ] && steps=2  # the simulator's set-up and steps cost minutes there
  /usr/bin/time -f "$n ranks: simulator wall %e s, max RSS %M KB (folded pages counted again)" \
    harness/simgrid/run.sh harness/simgrid/platforms/ricc.xml "$n" 8 build-simgrid/bin/weak_scaling \
    --method acm --steps "$steps" --csv "$out" | grep -E "timing over|comm fraction"
done
echo "wrote $out"
