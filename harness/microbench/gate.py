#!/usr/bin/python3
"""CI micro-benchmark gate on counted work (harness/microbench/README.md).

A counted run of bench_kernels (callgrind, ci/microbench_gate.sh) gives per kernel figures
that do not depend on the host or its load: instructions, estimated cycles from simulated
caches, MPI messages and bytes (callgrind_counts.py).  The gate compares them with the
committed baseline of the same build configuration; a timed run, when given, is printed
beside them as information and never gates.

  gate.py check RUN_DIR [--timed TIMED.json] [--baseline-dir DIR]
      prints the table and exits 1 when a figure leaves its tolerance (TOLERANCE: either
      way, since a deliberate optimisation moves the baseline in its own commit), a
      baseline kernel is missing, or no baseline exists for the run's build configuration.
  gate.py write RUN_DIR [--baseline-dir DIR] [--machine NAME]
      writes the baseline of the run's build configuration from the run.
  gate.py diff OLD.json NEW.json
      the before/after table (Markdown) a commit that moves the baseline carries.
  gate.py spread RUN_DIR [RUN_DIR ...]
      per kernel and figure, the largest relative difference over the runs.
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_json  # noqa: E402
import callgrind_counts  # noqa: E402

# The gated figures: the relative change each may show against the baseline, and a floor
# per unit of work below which a change is not counted.  Counts are deterministic up to a
# few instructions of heap bookkeeping (malloc's state depends on MPI's history); the cache
# estimate moves a little more, because MPI's own calls (left out of the counts, but run
# through the simulated caches) evict a few lines depending on when messages arrive.  That
# is noise only where a kernel's own work is a few dozen instructions (the global
# reduction: its work is MPI's), hence the floors.  The MPI census allows no change at all.
TOLERANCE = {
    "Ir": (0.02, 100),
    "est_cycles": (0.03, 1000),
    "mpi_messages": (0.0, 0),
    "mpi_bytes": (0.0, 0),
    "mpi_collectives": (0.0, 0),
    "mpi_collective_bytes": (0.0, 0),
}
EXACT = 1e-9  # what "no change" allows for a per-unit figure stored as a decimal
DEFAULT_DIR = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "results", "microbench", "baseline"))
REFRESH = "bash ci/microbench_gate.sh --refresh-baseline"


def baseline_path(directory, build):
    return os.path.join(directory, f"counts-{build}.json")


def relative(new, old):
    if old == 0:
        return 0.0 if new == 0 else float("inf")
    return new / old - 1.0


def check(run_dir, directory, timed):
    counts, ctx = callgrind_counts.load(run_dir)
    build = ctx.get("efsi_build", "?")
    path = baseline_path(directory, build)
    if not os.path.exists(path):
        print(f"GATE FAILED: no baseline for build configuration {build} ({path}); make it with {REFRESH}")
        return 1
    with open(path) as f:
        base = json.load(f)
    kernels = base["kernels"]
    names = list(kernels) + [n for n in counts if n not in kernels]
    w = max(len(n) for n in names)
    print(f"counted gate: {run_dir} against {os.path.relpath(path)} (build {build}; tolerances "
          + ", ".join(f"{k} {t:.0%} (floor {f})" for k, (t, f) in TOLERANCE.items() if t) + ", MPI census exact)")
    print(f"| {'kernel':<{w}} | {'Ir/unit':>12} | {'vs base':>8} | {'est.cycles':>12} | {'vs base':>8} "
          f"| {'msgs':>7} | {'MPI bytes':>11} | {'coll.':>6} | {'coll. bytes':>11} | status |")
    print(f"|{'-' * (w + 2)}|{'-' * 14}|{'-' * 10}|{'-' * 14}|{'-' * 10}|{'-' * 9}|{'-' * 13}|{'-' * 8}|{'-' * 13}|--------|")
    failed = []
    for name in names:
        row, b = counts.get(name), kernels.get(name)
        if row is None:
            print(f"| {name:<{w}} | {'-':>12} | {'-':>8} | {'-':>12} | {'-':>8} | {'-':>7} | {'-':>11} | {'-':>6} | {'-':>11} | MISSING |")
            failed.append(f"{name} (missing)")
            continue
        cells = f"| {name:<{w}} | {row['Ir']:12.6g} | "
        if b is None:
            print(cells + f"{'-':>8} | {row['est_cycles']:12.6g} | {'-':>8} | {row['mpi_messages']:7.4g} | "
                  f"{row['mpi_bytes']:11.6g} | {row['mpi_collectives']:6.3g} | {row['mpi_collective_bytes']:11.6g} | new    |")
            continue
        bad = []
        for fig, (tol, floor) in TOLERANCE.items():
            rel = relative(row[fig], b[fig])
            if abs(rel) > max(tol, EXACT) and abs(row[fig] - b[fig]) > floor:
                bad.append(f"{fig} {row[fig]:.6g} vs {b[fig]:.6g} ({rel:+.2%})")
        status = "FAIL" if bad else "ok"
        print(cells + f"{relative(row['Ir'], b['Ir']):+8.2%} | {row['est_cycles']:12.6g} | "
              f"{relative(row['est_cycles'], b['est_cycles']):+8.2%} | {row['mpi_messages']:7.4g} | "
              f"{row['mpi_bytes']:11.6g} | {row['mpi_collectives']:6.3g} | {row['mpi_collective_bytes']:11.6g} | {status:<6} |")
        failed += [f"{name}: {x}" for x in bad]
    if timed:
        print_times(timed)
    if failed:
        for f in failed:
            print(f"GATE FAILED: {f}")
        print(f"(a deliberate change moves the baseline: {REFRESH}, and gate.py diff OLD NEW in the commit)")
        return 1
    print("gate passed")
    return 0


def print_times(path):
    doc = bench_json.load(path)
    s = bench_json.summary(doc)
    ctx = doc.get("context", {})
    w = max(len(n) for n in s)
    print(f"\ntimes (information, not gating): {path}, build {ctx.get('efsi_build', '?')}, "
          f"{ctx.get('mpi_ranks', '?')} ranks, host {ctx.get('host_name', '?')}")
    print(f"| {'kernel':<{w}} | {'median us':>10} | {'CPU min us':>10} | {'GB/s':>7} | {'GFLOP/s':>7} | {'of triad':>8} | {'of roof':>7} |")
    print(f"|{'-' * (w + 2)}|{'-' * 12}|{'-' * 12}|{'-' * 9}|{'-' * 9}|{'-' * 10}|{'-' * 9}|")
    for name, r in s.items():
        print(f"| {name:<{w}} | {r['median_us']:10.4g} | {r['cpu_min_us']:10.4g} | {r['GBps']:7.3g} | "
              f"{r['GFLOPs']:7.3g} | {r['roofline_fraction']:8.3f} | {r.get('roof_fraction', 0.0):7.3f} |")


def write(run_dir, directory, machine):
    counts, ctx = callgrind_counts.load(run_dir)
    build = ctx.get("efsi_build", "?")
    doc = {
        "about": "bench_kernels counted work per unit (callgrind; harness/microbench/README.md), one build configuration",
        "build": build,
        "made_on": machine,
        "command": REFRESH,
        "kernels": counts,
    }
    os.makedirs(directory, exist_ok=True)
    path = baseline_path(directory, build)
    with open(path, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print(f"wrote {path}: {len(counts)} kernels")
    return 0


def diff(old_path, new_path):
    with open(old_path) as f:
        old = json.load(f)["kernels"]
    with open(new_path) as f:
        new = json.load(f)["kernels"]
    print("| kernel | Ir/unit before | after | change | est. cycles before | after | change | messages | MPI bytes |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for name in list(old) + [n for n in new if n not in old]:
        o, n = old.get(name), new.get(name)
        if o is None or n is None:
            print(f"| {name} | {'added' if o is None else 'removed'} |||||||")
            continue
        msgs = f"{o['mpi_messages']:.4g}" + ("" if o["mpi_messages"] == n["mpi_messages"] else f" -> {n['mpi_messages']:.4g}")
        nbytes = f"{o['mpi_bytes']:.6g}" + ("" if o["mpi_bytes"] == n["mpi_bytes"] else f" -> {n['mpi_bytes']:.6g}")
        print(f"| {name} | {o['Ir']:.6g} | {n['Ir']:.6g} | {relative(n['Ir'], o['Ir']):+.1%} | {o['est_cycles']:.6g} | "
              f"{n['est_cycles']:.6g} | {relative(n['est_cycles'], o['est_cycles']):+.1%} | {msgs} | {nbytes} |")
    return 0


def spread(run_dirs):
    runs = [callgrind_counts.load(d)[0] for d in run_dirs]
    figures = list(TOLERANCE) + ["D1_misses", "LL_misses"]
    print(f"spread over {len(runs)} runs: (max - min) / min per kernel and figure")
    print("| kernel | " + " | ".join(figures) + " |")
    print("|---|" + "---:|" * len(figures))
    worst = {f: 0.0 for f in figures}
    for name in runs[0]:
        cells = []
        for f in figures:
            vals = [r[name][f] for r in runs if name in r]
            lo, hi = min(vals), max(vals)
            rel = (hi - lo) / lo if lo else (0.0 if hi == 0 else float("inf"))
            worst[f] = max(worst[f], rel)
            cells.append(f"{rel:.2e}")
        print(f"| {name} | " + " | ".join(cells) + " |")
    print("| worst | " + " | ".join(f"{worst[f]:.2e}" for f in figures) + " |")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    c = sub.add_parser("check")
    c.add_argument("run_dir")
    c.add_argument("--timed", help="a timed bench_kernels JSON to print beside (not gating)")
    c.add_argument("--baseline-dir", default=DEFAULT_DIR)
    w = sub.add_parser("write")
    w.add_argument("run_dir")
    w.add_argument("--baseline-dir", default=DEFAULT_DIR)
    w.add_argument("--machine", default="dev-2core")
    d = sub.add_parser("diff")
    d.add_argument("old")
    d.add_argument("new")
    s = sub.add_parser("spread")
    s.add_argument("run_dirs", nargs="+")
    a = ap.parse_args()
    if a.cmd == "check":
        return check(a.run_dir, a.baseline_dir, a.timed)
    if a.cmd == "write":
        return write(a.run_dir, a.baseline_dir, a.machine)
    if a.cmd == "diff":
        return diff(a.old, a.new)
    return spread(a.run_dirs)


if __name__ == "__main__":
    sys.exit(main())
