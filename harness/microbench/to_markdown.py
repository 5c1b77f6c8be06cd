#!/usr/bin/python3
"""Markdown table of a bench_kernels JSON run (harness/microbench/README.md).

  to_markdown.py RUN.json [--machine dev-2core] [> table.md]

Columns: median time per call (median over repetitions of each repetition's median
iteration), counted bytes and flops per cell, achieved GB/s and GFLOP/s per rank from the
median time, and the fraction of the in-run STREAM-triad bandwidth the kernel reaches: its
GB/s over the triad's best per-rank bandwidth in the run (all ranks streaming together; the
same figure for every row, in the heading), and its fraction of the roofline: its GFLOP/s over
its roof time over its median time, the roof time being the larger of its counted bytes at
the triad's best bandwidth and its counted flops at the best compute roofs: the WENO5 part
at the WENO5 probe's rate, the rest at the multiply-add probe's (a kernel that counts no
flops, such as the halo exchange, has only the triad's).  The gate's counted figures are in gate.py's table.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_json  # noqa: E402


def roof_fraction(r, triad, compute, weno):
    """The kernel's roof time over its measured time at the run's best probes, as text; ''
    where the run has no compute probe.  The roof time is the larger of the counted bytes at
    the triad's bandwidth and the counted flops at the compute roofs: the WENO5 part at the
    WENO5 probe's rate (where the run has one), the rest at the multiply-add probe's."""
    if compute <= 0:
        return ""
    if r["flops_per_cell"] <= 0 or r["bytes_per_cell"] <= 0:  # the triad is its only roof
        return f"{r['GBps'] / triad:.3f}"
    flops, nbytes = r["flops_per_cell"], r["bytes_per_cell"]
    w = r.get("weno_flops_per_cell", 0.0) if weno > 0 else 0.0
    roof = max(nbytes / triad, (flops - w) / compute + (w / weno if w > 0 else 0.0))
    return f"{roof * r['GFLOPs'] / flops:.3f}"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("run")
    ap.add_argument("--machine", default="dev-2core")
    a = ap.parse_args()
    doc = bench_json.load(a.run)
    s = bench_json.summary(doc)
    probe = bench_json.probe_us(doc, "triad_us")
    ctx = doc.get("context", {})
    triad = max(r["triad_GBps"] for r in s.values())  # from the run's fastest pass
    compute = max(r["compute_GFLOPs"] for r in s.values())
    weno = max(r.get("weno_GFLOPs", 0.0) for r in s.values())
    print(f"Machine `{a.machine}`, {ctx.get('mpi_ranks', '?')} MPI ranks x {ctx.get('omp_threads', '?')} "
          f"OpenMP threads, {ctx.get('date', '')}; STREAM triad {triad:.1f} GB/s per rank "
          f"(fastest pass {probe:.0f} us), compute probe {compute:.1f} GFLOP/s per rank"
          + (f", WENO5 probe {weno:.1f} GFLOP/s per rank" if weno > 0 else "") + ".\n")
    print("| kernel | median time (us) | B/cell | flop/cell | GB/s | GFLOP/s | fraction of triad | fraction of roof |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, r in s.items():
        print(f"| {name} | {r['median_us']:.4g} | {r['bytes_per_cell']:.4g} | {r['flops_per_cell']:.4g} | "
              f"{r['GBps']:.3g} | {r['GFLOPs']:.3g} | {r['GBps'] / triad:.3f} | {roof_fraction(r, triad, compute, weno)} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
