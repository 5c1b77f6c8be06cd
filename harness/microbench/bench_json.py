"""Reading Google Benchmark JSON written by bench_kernels (harness/microbench/README.md).

Every benchmark row carries the counters of kernel_timing.hpp.  With
--benchmark_repetitions=R a benchmark has R iteration rows (and aggregate rows, which are
skipped here: the figures below are recomputed from the iteration rows).
"""
import json
import statistics


def load(path):
    with open(path) as f:
        return json.load(f)


def runs_by_benchmark(doc):
    """{benchmark name: [iteration rows]} in the order of the file (name without the
    /manual_time suffix)."""
    out = {}
    for row in doc.get("benchmarks", []):
        if row.get("run_type", "iteration") != "iteration" or "min_us" not in row:
            continue
        if row.get("error_occurred"):
            continue
        name = row.get("run_name", row["name"]).replace("/manual_time", "")
        out.setdefault(name, []).append(row)
    return out


def probe_us(doc, key="cache_triad_cpu_us"):
    """A probe's least time over the whole run (us): the cache-resident triad's CPU time (the
    gate's unit), or key="triad_us" for the memory triad's wall time.  Every benchmark runs
    the probes kProbePasses times after its loop, so this is the minimum of many passes
    spread over the run, the least disturbed measure the run had."""
    rows = [r for rs in runs_by_benchmark(doc).values() for r in rs]
    return min(r[key] for r in rows if r.get(key, 0) > 0)


def summary(doc):
    """Per benchmark: min_us, cpu_min_us and gate_us (least over all repetitions: wall time,
    CPU time, and the gate's CPU figure, kernel_timing.hpp), median_us (median over
    repetitions of each repetition's median iteration), and the median over repetitions of
    the counted GBps, GFLOPs and roofline_fraction; ratio = gate_us / the run's probe_us, or,
    for a row with a comm_probe_cpu_us counter (the global reduction), gate_us / the least
    comm_probe_cpu_us of that benchmark's repetitions (the MPI latency probe measured right
    after it)."""
    probe = probe_us(doc)
    out = {}
    for name, rows in runs_by_benchmark(doc).items():
        med = lambda key: statistics.median(r.get(key, 0.0) for r in rows)
        t_min = min(r["min_us"] for r in rows)
        cpu_min = min(r["cpu_min_us"] for r in rows)
        gate_min = min(r["gate_us"] for r in rows)
        unit = min(r["comm_probe_cpu_us"] for r in rows) if "comm_probe_cpu_us" in rows[0] else probe
        out[name] = {
            "min_us": t_min,
            "cpu_min_us": cpu_min,
            "median_us": med("median_us"),
            "GBps": med("GBps"),
            "GFLOPs": med("GFLOPs"),
            "roofline_fraction": med("roofline_fraction"),
            "triad_GBps": med("triad_GBps"),
            "bytes_per_cell": rows[0].get("bytes_per_cell", 0.0),
            "flops_per_cell": rows[0].get("flops_per_cell", 0.0),
            "repetitions": len(rows),
            "gate_us": gate_min,
            "ratio": gate_min / unit,
        }
    return out, probe
