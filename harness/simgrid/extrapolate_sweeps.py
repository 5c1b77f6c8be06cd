#!/usr/bin/env python3
"""SOR's step at the paper's sweep counts from short simulated steps: an extrapolation,
labelled as one, for the rank counts where a full step costs the simulator too much.

A simulated SOR step is the same work and the same messages sweep after sweep, so its
time is linear in the SOR sweeps N_S and the Crank-Nicolson sweeps N_C of the step:

    t(N_S, N_C) = a + b N_S + c N_C        (and the same for the communication time)

Three simulated steps of one configuration, at (s, n), (s + ds, n) and (s, n + dn), give
a, b and c; the step at the paper's (N_S, N_C) for the row's experiment and tolerance (Table 1
weak, Table 3 strong, as the mean a step) follows.
Where a full simulation at the paper's counts exists (--full CSV), the extrapolation is
checked against it: the relative gap must stay under AGREE (one PASSED/FAILED line; exit
status 1 on FAILED).  Prints a Markdown table: ranks, rank grid, the extrapolated time of
the paper's step count, and the communication fraction.

  extrapolate_sweeps.py --parts results/simulated/ricc-weak-sor-parts.csv \\
                        --full results/simulated/ricc-weak-sor.csv

Standard library only; Debian's /usr/bin/python3.
"""

import argparse
import collections
import csv
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import paper_tables  # noqa: E402

PROG = "extrapolate_sweeps.py"
# The largest relative gap to a full simulation that counts as agreement.  A short async step
# overlaps its few exchanges less evenly than a full one, so the fit's error grows with the
# communication fraction: 0.06% at 512 ranks with one SOR efficiency for the step (comm
# fraction 0.08), 1.0% with the sweeps' own (0.14).  2% changes no verdict against the
# paper, which the predictions are judged on within 15%.
AGREE = 0.02


class Error(Exception):
    pass


def read_rows(path):
    with open(path, newline="") as f:
        return [r for r in csv.DictReader(f) if r.get("valid") == "1" and r.get("method") == "sor"]


def per_step(row, column):
    return float(row[column]) / int(row["steps"])


def fit(points):
    """points: {(ns, nc): row} with three corners (s, n), (s + ds, n), (s, n + dn) -> a function
    (column, ns, nc) -> the column's value per step, linear in ns and nc."""
    keys = sorted(points)
    base = min(keys)
    up_s = [k for k in keys if k[1] == base[1] and k[0] > base[0]]
    up_c = [k for k in keys if k[0] == base[0] and k[1] > base[1]]
    if not up_s or not up_c:
        raise Error(f"need steps at (s, n), (s + ds, n) and (s, n + dn); have {keys}")
    ks, kc = up_s[0], up_c[0]

    def value(column, ns, nc):
        t0 = per_step(points[base], column)
        b = (per_step(points[ks], column) - t0) / (ks[0] - base[0])
        c = (per_step(points[kc], column) - t0) / (kc[1] - base[1])
        return t0 + b * (ns - base[0]) + c * (nc - base[1])

    return value


def main(argv=None):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    ap.add_argument("--parts", required=True, help="simulated short SOR steps (three (N_S, N_C) a configuration)")
    ap.add_argument("--full", help="simulated steps at the paper's counts, to check the extrapolation against")
    args = ap.parse_args(argv)
    try:
        sweeps = paper_tables.sor_sweeps()
        # A short step runs its --ns and --nc whatever its --eps: one set of three serves
        # every tolerance of its experiment.
        groups = collections.defaultdict(dict)
        for r in read_rows(args.parts):
            key = (r["experiment"], r["simulated"], r["comm"], int(r["ranks"]))
            groups[key][(int(r["ns_per_step"]), int(r["nc_per_step"]))] = r
        if not groups:
            raise Error(f"{args.parts}: no valid SOR rows")
        full = {}
        for r in read_rows(args.full) if args.full else []:
            key = (r["experiment"], r["simulated"], r["comm"], int(r["ranks"]))
            full[(key, int(r["ns_per_step"]), int(r["nc_per_step"]))] = per_step(r, "elapsed_s")
        worst, checked = 0.0, 0
        tables = collections.defaultdict(list)
        for key in sorted(groups):
            experiment, platform, comm, ranks = key
            if len(groups[key]) < 3:  # a campaign still under way
                print(f"{PROG}: {experiment} {ranks} ranks, SOR {comm}: {len(groups[key])} of 3 short steps, left out",
                      file=sys.stderr)
                continue
            tolerances = sorted(e for (x, e) in sweeps if x == experiment)
            if not tolerances:
                raise Error(f"no {experiment} SOR sweep counts in {paper_tables.PAPER_TABLES}")
            value = fit(groups[key])
            row = next(iter(groups[key].values()))
            for eps in tolerances:
                ns, nc, steps = sweeps[(experiment, eps)]
                t = value("elapsed_s", ns, nc)
                comm_s = value("comm_s", ns, nc)
                simulated = full.get((key, int(ns), int(nc))) if ns == int(ns) and nc == int(nc) else None
                shown = ""
                if simulated is not None:
                    gap = abs(t / simulated - 1)
                    worst, checked = max(worst, gap), checked + 1
                    shown = f"{simulated * steps:.2f} (gap {gap:.2%})"
                tables[(experiment, platform, comm, eps, ns, nc, steps)].append(
                    f"| {ranks} | {row['px']}x{row['py']}x{row['pz']} | {t * steps:.2f} | {shown} | {comm_s / t:.3f} |")
        for (experiment, platform, comm, eps, ns, nc, steps), lines in sorted(tables.items()):
            print(f"\n### SOR {experiment} {comm} {eps} on {platform}, extrapolated to N_S = {ns:g}, N_C = {nc:g}\n")
            print(f"| ranks | rank grid | extrapolated (s, {steps} steps) | full simulation (s) | comm fraction |")
            print("|---|---|---|---|---|")
            print("\n".join(lines))
        print()
        if args.full:
            if checked == 0:
                raise Error(f"{args.full}: no full simulation at the paper's counts to check against")
            verdict = "PASSED" if worst < AGREE else "FAILED"
            print(f"extrapolation against {checked} full simulations: largest gap {worst:.3%} "
                  f"(limit {AGREE:.1%}): {verdict}")
            return 0 if verdict == "PASSED" else 1
    except (Error, OSError, KeyError, ValueError) as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
