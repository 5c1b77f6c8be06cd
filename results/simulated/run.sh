#!/usr/bin/env bash
# The committed predictions of results/simulated/ (README.md there): the paper's campaigns
# on the RICC model and on RICC's tree with today's parts, through harness/campaign.py
# simulate (restartable: run it again and it goes on where it stopped).
#   results/simulated/run.sh                 every sweep below (hours on a 2-core machine)
#   results/simulated/run.sh weak|strong|modern|sor|sor-parts
# Needs the simulation build (cmake --preset simgrid && cmake --build --preset simgrid) and,
# from 512 ranks, vm.max_map_count raised (sysctl -w vm.max_map_count=4194304).
set -euo pipefail
cd "$(dirname "$0")/../.."
campaign=(python3 harness/campaign.py simulate)
what=("$@")
[ ${#what[@]} -gt 0 ] || what=(weak strong modern sor sor-parts)
for w in "${what[@]}"; do
  case "$w" in
    # ACM, Table 2: 1 to 8192 ranks, 8 a node, 2 measured steps.
    weak) "${campaign[@]}" --platform ricc --sweep weak --configs acm-sync --csv results/simulated/ricc-weak.csv ;;
    # ACM, Table 4: the 2048 x 1024 x 1024 case on 1024 to 8192 ranks.
    strong) "${campaign[@]}" --platform ricc --sweep strong --configs acm-sync --csv results/simulated/ricc-strong.csv ;;
    # The same weak sweep on ricc-modern: what the faster kernel does to the communication fraction.
    modern) "${campaign[@]}" --platform ricc-modern --sweep weak --configs acm-sync \
              --ranks 1,8,64,512,4096,8192 --csv results/simulated/ricc-modern-weak.csv ;;
    # SOR, one measured step a point: at 1e-3 (N_S = 100, N_C = 20) async and sync to 512 ranks,
    # at 1e-4 (N_S = 220) both to 64.  A step's 480 exchanges cost the simulator about 3x a
    # doubling: 228 to 393 s at 512 ranks (README.md).
    sor) "${campaign[@]}" --platform ricc --sweep weak --configs sor-async-1e-3,sor-sync-1e-3 \
           --ranks 1,2,4,8,16,32,64,128,256,512 --steps 1 --csv results/simulated/ricc-weak-sor.csv
         "${campaign[@]}" --platform ricc --sweep weak --configs sor-async-1e-4,sor-sync-1e-4 \
           --ranks 1,2,4,8,16,32,64 --steps 1 --csv results/simulated/ricc-weak-sor.csv ;;
    # Short SOR steps, (N_S, N_C) = (2, 2), (4, 2), (2, 4), for harness/simgrid/extrapolate_sweeps.py
    # (not restartable: delete the CSV first).
    sor-parts)
      for n in 8 64 512 1024; do for p in "2 2" "4 2" "2 4"; do set -- $p
        harness/simgrid/run.sh harness/simgrid/platforms/ricc.xml $n 8 build-simgrid/bin/weak_scaling \
          --method sor --comm async --eps 1e-3 --ns "$1" --nc "$2" --halo phased --steps 1 \
          --csv results/simulated/ricc-weak-sor-parts.csv
      done; done ;;
    *) echo "run.sh: unknown sweep '$w' (weak, strong, modern, sor, sor-parts)" >&2; exit 2 ;;
  esac
done
