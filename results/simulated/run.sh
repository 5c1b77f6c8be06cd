#!/usr/bin/env bash
# The committed predictions of results/simulated/ (README.md there): the paper's campaigns
# on the RICC model and on RICC's tree with today's parts, through harness/campaign.py
# simulate (restartable: run it again and it goes on where it stopped).
#   results/simulated/run.sh                 every sweep below (hours on a 2-core machine)
#   results/simulated/run.sh weak|strong|modern|sor|sor-parts|sor-parts-large|sor-strong-parts
# Needs the simulation build (cmake --preset simgrid && cmake --build --preset simgrid) and,
# from 512 ranks, vm.max_map_count raised (sysctl -w vm.max_map_count=4194304).
set -euo pipefail
cd "$(dirname "$0")/../.."
campaign=(python3 harness/campaign.py simulate)
what=("$@")
[ ${#what[@]} -gt 0 ] || what=(weak strong modern sor sor-parts sor-parts-large sor-strong-parts)
# Short SOR steps at (N_S, N_C) = (2, 2), (4, 2), (2, 4) on RANKS ranks of DRIVER into CSV.
short_sor_steps() {
  local driver=$1 ranks=$2 comm=$3 csv=$4 ns nc p
  shift 4
  for p in "2 2" "4 2" "2 4"; do
    read -r ns nc <<< "$p"
    harness/simgrid/run.sh harness/simgrid/platforms/ricc.xml "$ranks" 8 "build-simgrid/bin/$driver" \
      --method sor --comm "$comm" --eps 1e-3 --ns "$ns" --nc "$nc" --halo phased --steps 1 "$@" --csv "$csv"
  done
}
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
    # From 2048 ranks, the short steps with SimGrid's event precision at 1 us (surf/precision,
    # 1e-9 s by default): events closer than that are taken together.  At 1024 ranks this
    # halved the simulator's time and moved the step by 0.1%; at 512, by at most 0.05%
    # (harness/simgrid/README.md).  Not restartable: delete the rows first.
    sor-parts-large)
      for comm in async sync; do
        EFSI_SMPI_CFG="--cfg=surf/precision:1e-6" short_sor_steps weak_scaling 2048 $comm results/simulated/ricc-weak-sor-parts.csv
      done
      EFSI_SMPI_CFG="--cfg=surf/precision:1e-6" short_sor_steps weak_scaling 4096 async results/simulated/ricc-weak-sor-parts.csv ;;
    # Table 4's SOR: short steps of the strong case on the ACM's rank grids (the paper's
    # decomposition; SOR alone would take 1 x PY x PZ, its fused-pair grid), 1e-6 as above.
    sor-strong-parts)
      for n_grid in 1024:8,16,8 2048:8,16,16; do n=${n_grid%%:*}; grid=${n_grid#*:}
        for comm in async sync; do
          EFSI_SMPI_CFG="--cfg=surf/precision:1e-6" short_sor_steps strong_scaling $n $comm \
            results/simulated/ricc-strong-sor-parts.csv --decomp $grid
        done
      done ;;
    *) echo "run.sh: unknown sweep '$w' (weak, strong, modern, sor, sor-parts, sor-parts-large, sor-strong-parts)" >&2; exit 2 ;;
  esac
done
