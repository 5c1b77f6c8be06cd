"""Counted work per kernel from a counted bench_kernels run (harness/microbench/README.md).

The run (EFSI_COUNT=1 under callgrind, ci/microbench_gate.sh) leaves, per rank r, callgrind
parts DIR/cg.r.N, each headed "desc: Trigger: Client Request: KERNEL" with the events of
that kernel's measured calls on its "summary:" line, and rank 0's Google Benchmark JSON with
the kernel's MPI census and its units of work (kernel_timing.hpp).

Figures per unit of work (one call; one SOR sweep), the most over ranks (the slowest rank
sets a step's pace):
  Ir                instructions executed (MPI's own calls left out)
  est_cycles        L1 hits + 5 x LL hits + 35 x memory accesses, from the simulated caches:
                    the estimate iai-callgrind and CodSpeed use
  D1_misses, LL_misses   the simulated misses (information)
  mpi_messages, mpi_bytes, mpi_collectives, mpi_collective_bytes   the census
"""
import glob
import json
import os
import re

CENSUS = ("mpi_messages", "mpi_bytes", "mpi_collectives", "mpi_collective_bytes")
SUFFIX = re.compile(r"/(iterations|repeats):\d+|/manual_time")


def benchmark_name(row):
    return SUFFIX.sub("", row.get("run_name", row["name"]))


def read_part(path):
    """(kernel name, {event: count}) of one callgrind part, or None for a part no kernel
    dumped (the one written at exit)."""
    name, events, summary = None, None, None
    with open(path, errors="replace") as f:
        for line in f:
            if line.startswith("desc: Trigger: Client Request: "):
                name = line[len("desc: Trigger: Client Request: "):].strip()
            elif line.startswith("events: "):
                events = line.split()[1:]
            elif line.startswith("summary: "):
                summary = [int(v) for v in line.split()[1:]]
                break
    if name is None or events is None or summary is None:
        return None
    summary += [0] * (len(events) - len(summary))  # callgrind drops trailing zeros
    return name, dict(zip(events, summary))


def derived(ev):
    """Ir, est_cycles and the misses from one part's events."""
    l1_miss = ev["I1mr"] + ev["D1mr"] + ev["D1mw"]
    ll_miss = ev["ILmr"] + ev["DLmr"] + ev["DLmw"]
    refs = ev["Ir"] + ev["Dr"] + ev["Dw"]
    return {
        "Ir": ev["Ir"],
        "est_cycles": (refs - l1_miss) + 5 * (l1_miss - ll_miss) + 35 * ll_miss,
        "D1_misses": ev["D1mr"] + ev["D1mw"],
        "LL_misses": ll_miss,
    }


def load(run_dir):
    """{kernel: {figure: value per unit}} and the run's context (build configuration, ranks)."""
    with open(os.path.join(run_dir, "counts.json")) as f:
        doc = json.load(f)
    rows = {benchmark_name(r): r for r in doc.get("benchmarks", []) if "units" in r and not r.get("error_occurred")}
    per_rank = {}
    for path in glob.glob(os.path.join(run_dir, "cg.*.*")):
        part = read_part(path)
        if part is None:
            continue
        name, ev = part
        figures = derived(ev)
        best = per_rank.setdefault(name, {k: 0 for k in figures})
        for k, v in figures.items():
            best[k] = max(best[k], v)
    out = {}
    for name, row in rows.items():
        if name not in per_rank:
            raise SystemExit(f"{run_dir}: no callgrind part for {name} (was the run made under callgrind?)")
        units = row["units"]
        fig = {k: v / units for k, v in per_rank[name].items()}
        fig.update({k: row[k] for k in CENSUS})
        out[name] = fig
    return out, doc.get("context", {})
