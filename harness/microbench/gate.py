#!/usr/bin/python3
"""CI micro-benchmark gate: compares each kernel's machine-independent ratio with a
committed baseline (harness/microbench/README.md).

ratio = the kernel's least CPU time per call over all iterations and repetitions / the
cache-resident STREAM-triad probe's least CPU time over all its passes in the same run
(bench_json.summary, stream_probe.hpp).
The kernel's CPU time is its CPU time outside MPI's blocking calls (for the halo exchange
and the global reduction, whose work is communication: the CPU time of the rank that used
least; kernel_clock.hpp), and the reduction takes its ratio over an in-run MPI latency probe
instead of the triad.  CPU time, because a rank preempted by another job loses wall time but not CPU time;
least, because what load adds only ever slows a sample down.

  gate.py RUN.json [RERUN.json ...] --baseline BASE.json [--factor 1.5] [--failed-list F]
      prints a table of every ratio and exits 1 when a ratio exceeds factor x its baseline
      or a baseline kernel is missing from the runs.  With several runs (ci/microbench_gate.sh
      reruns the kernels that failed, at most twice) a kernel's ratio is the least of its
      runs': a slowdown that is real shows in every run, one from a busy machine does not.
      --failed-list writes the failing kernels' names, one a line, for that rerun.
  gate.py RUN1.json [RUN2.json ...] --write-baseline BASE.json [--machine NAME]
      writes the baseline: per kernel the median of the runs' ratios.
"""
import argparse
import json
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_json  # noqa: E402


def write_baseline(paths, out, machine, command):
    ratios, probes = {}, []
    for p in paths:
        s, probe = bench_json.summary(bench_json.load(p))
        probes.append(probe)
        for name, row in s.items():
            ratios.setdefault(name, []).append(row["ratio"])
    doc = {
        "about": "bench_kernels ratios (kernel least CPU time / in-run triad probe least CPU time), "
                 "median over the runs; refresh with harness/microbench/README.md",
        "machine": machine,
        "command": command,
        "runs": len(paths),
        "probe_us": statistics.median(probes),
        "ratios": {k: statistics.median(v) for k, v in ratios.items()},
    }
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with open(out, "w") as f:
        json.dump(doc, f, indent=2, sort_keys=False)
        f.write("\n")
    print(f"wrote {out}: {len(doc['ratios'])} kernels from {len(paths)} run(s)")


def gate(paths, baseline_path, factor, failed_list=None):
    s, probe = {}, None
    for path in paths:
        one, p = bench_json.summary(bench_json.load(path))
        probe = p if probe is None else probe
        for name, row in one.items():
            if name not in s or row["ratio"] < s[name]["ratio"]:
                s[name] = row
    with open(baseline_path) as f:
        base = json.load(f)
    ratios = base["ratios"]
    names = list(ratios) + [n for n in s if n not in ratios]
    w = max(len(n) for n in names)
    print(f"micro-benchmark gate: {' + '.join(paths)} vs {baseline_path} (fail above {factor} x baseline)")
    print(f"cache-triad probe (CPU time): {probe:.1f} us in the first run, {base.get('probe_us', 0):.1f} us in the baseline "
          f"({base.get('machine', '?')})")
    print(f"| {'kernel':<{w}} | {'CPU us':>10} | {'ratio':>9} | {'baseline':>9} | {'ratio/base':>10} | status |")
    print(f"|{'-' * (w + 2)}|{'-' * 12}|{'-' * 11}|{'-' * 11}|{'-' * 12}|--------|")
    failed, worst = [], 0.0
    for name in names:
        row, b = s.get(name), ratios.get(name)
        if row is None:
            print(f"| {name:<{w}} | {'-':>10} | {'-':>9} | {b:9.4g} | {'-':>10} | MISSING |")
            failed.append(name)
            continue
        if b is None:
            print(f"| {name:<{w}} | {row['gate_us']:10.4g} | {row['ratio']:9.4g} | {'-':>9} | {'-':>10} | new    |")
            continue
        rel = row["ratio"] / b
        worst = max(worst, rel)
        status = "FAIL" if rel > factor else "ok"
        if rel > factor:
            failed.append(name)
        print(f"| {name:<{w}} | {row['gate_us']:10.4g} | {row['ratio']:9.4g} | {b:9.4g} | {rel:10.3f} | {status:<6} |")
    print(f"worst ratio/baseline: {worst:.3f}")
    if failed_list:
        with open(failed_list, "w") as f:
            f.writelines(n + "\n" for n in failed)
    if failed:
        print(f"GATE FAILED: {', '.join(failed)}")
        return 1
    print("gate passed")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="bench_kernels JSON output(s)")
    ap.add_argument("--baseline", help="committed baseline to compare with")
    ap.add_argument("--factor", type=float, default=1.5)
    ap.add_argument("--write-baseline", metavar="OUT", help="write a baseline from the runs instead")
    ap.add_argument("--machine", default="dev-2core", help="machine name recorded in a written baseline")
    ap.add_argument("--command", default="ci/microbench_gate.sh", help="command recorded in a written baseline")
    ap.add_argument("--failed-list", metavar="FILE", help="write the failing kernels' names here")
    a = ap.parse_args()
    if a.write_baseline:
        write_baseline(a.runs, a.write_baseline, a.machine, a.command)
        return 0
    if not a.baseline:
        ap.error("give --baseline (or --write-baseline)")
    return gate(a.runs, a.baseline, a.factor, a.failed_list)


if __name__ == "__main__":
    sys.exit(main())
