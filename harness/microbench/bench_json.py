"""Reading the Google Benchmark JSON of a timed bench_kernels run (harness/microbench/README.md).

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


def probe_us(doc, key="triad_us"):
    """The STREAM-triad probe's least time over the whole run (us): every benchmark runs it
    kProbePasses times after its loop, so this is the least disturbed pass the run had."""
    rows = [r for rs in runs_by_benchmark(doc).values() for r in rs]
    return min(r[key] for r in rows if r.get(key, 0) > 0)


def summary(doc):
    """Per benchmark: min_us and cpu_min_us (least over all repetitions: wall time, CPU
    time; kernel_timing.hpp), median_us (median over repetitions of each repetition's median
    iteration), and the median over repetitions of the counted GBps, GFLOPs,
    roofline_fraction, the compute and WENO5 probes' GFLOP/s and roof_fraction.  Times are information: nothing gates on them."""
    out = {}
    for name, rows in runs_by_benchmark(doc).items():
        med = lambda key: statistics.median(r.get(key, 0.0) for r in rows)
        out[name] = {
            "min_us": min(r["min_us"] for r in rows),
            "cpu_min_us": min(r["cpu_min_us"] for r in rows),
            "median_us": med("median_us"),
            "GBps": med("GBps"),
            "GFLOPs": med("GFLOPs"),
            "roofline_fraction": med("roofline_fraction"),
            "compute_GFLOPs": med("compute_GFLOPs"),
            "weno_GFLOPs": med("weno_GFLOPs"),
            "roof_fraction": med("roof_fraction"),
            "triad_GBps": med("triad_GBps"),
            "bytes_per_cell": rows[0].get("bytes_per_cell", 0.0),
            "flops_per_cell": rows[0].get("flops_per_cell", 0.0),
            "weno_flops_per_cell": rows[0].get("weno_flops_per_cell", 0.0),
            "repetitions": len(rows),
        }
    return out
