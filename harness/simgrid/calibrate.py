#!/usr/bin/env python3
"""Fits a platform's compute efficiency per method on one-rank reference times.

The simulation build charges each stage t = max(flops / F, bytes / B_rank) / e
(kernels/grid/compute_model.hpp).  On one rank no message leaves the rank, so the simulated
time of a run is A / e, with A its time at e = 1: one run at e = 1 and the reference time T
give e = A / T.  The fitted e is written into the platform as the host property
efficiency:METHOD (--write) and every later simulation on that platform uses it.

SOR's step is two kinds of work: its Poisson sweeps (few flops a cell, over memory) and the
rest (the stencils of the step and Crank-Nicolson's sweeps).  The paper gives one-core
times at two tolerances, the same step with 100 and 220 sweeps, so SOR gets two
efficiencies: with R and S the rest's and the sweeps' simulated times at e = 1 (the sweeps'
are what halving their efficiency adds), T = R / e + S / e_sweeps at both tolerances fixes both
(efficiency:sor and efficiency:sor-sweeps).

  calibrate.py --platform harness/simgrid/platforms/ricc.xml --sim-bin-dir build-simgrid/bin \\
               --reference paper [--write]

--reference paper: the paper's one-core times of Table 2 (results/paper/paper_tables.csv):
ACM (50 steps, sync) and SOR sync at 1e-3 and 1e-4 (10 steps, the paper's N_S 100 and 220,
N_C 20).
--reference CSV: the valid one-rank rows of a measured weak-scaling CSV, the median time of
each method's first configuration (this machine's: the dev-2core platform).  Prints one line per method.  Standard library
only; Debian's /usr/bin/python3.
"""

import argparse
import csv
import os
import re
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import paper_tables  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
PROG = "calibrate.py"


class Error(Exception):
    pass


def paper_points():
    """(method, weak_scaling options, seconds) of Table 2 at one core: ACM, SOR sync at 1e-3
    and at 1e-4 (in that order), SOR at the paper's sweep counts for its tolerance (Table 1)."""
    sweeps = paper_tables.sor_sweeps()
    rows = [r for r in paper_tables.rows() if r["table"] == "2" and r["cores"] == "1" and r["comm"] == "sync"]
    points = []
    for r in rows:
        steps = int(r["steps"])
        eps = paper_tables.eps_label(r["eps"])
        if r["method"] == "acm":
            points.append(("acm", ["--method", "acm", "--steps", str(steps)], float(r["elapsed_s"])))
        elif r["method"] == "sor" and eps in ("1e-3", "1e-4"):
            ns, nc, _ = sweeps[("weak", eps)]
            points.append(("sor", ["--method", "sor", "--comm", "sync", "--ns", f"{ns:g}", "--nc", f"{nc:g}",
                                   "--steps", str(steps)], float(r["elapsed_s"])))
    if [p[0] for p in points].count("acm") != 1 or [p[0] for p in points].count("sor") != 2:
        raise Error(f"{paper_tables.PAPER_TABLES}: need the one-core sync rows of Table 2 for acm and for sor at 1e-3 and 1e-4")
    points.sort(key=lambda p: (p[0], float(p[1][p[1].index("--ns") + 1]) if "--ns" in p[1] else 0))
    return points


def measured_points(path):
    """(method, options, seconds): the one-rank weak-scaling rows of a measured CSV, the
    median elapsed time of the first configuration of each method (repeat the run and
    alternate it with others: one machine's times move)."""
    chosen, times = {}, {}
    with open(path, newline="") as f:
        for r in csv.DictReader(f):
            if r.get("experiment") != "weak" or r.get("ranks") != "1" or r.get("simulated") or r.get("valid") != "1":
                continue
            opts = ["--method", r["method"], "--comm", r["comm"], "--steps", r["steps"],
                    "--local", str(int(r["nx"]))]
            if r["ns_per_step"]:
                opts += ["--ns", r["ns_per_step"]]
            if r["nc_per_step"]:
                opts += ["--nc", r["nc_per_step"]]
            if chosen.setdefault(r["method"], opts) == opts:
                times.setdefault(r["method"], []).append(float(r["elapsed_s"]))
    if not chosen:
        raise Error(f"{path}: no valid measured one-rank weak-scaling row")
    return [(m, chosen[m], statistics.median(times[m])) for m in chosen]


def without_efficiency(xml, method):
    """The platform without efficiency:METHOD and efficiency:METHOD-sweeps."""
    return re.sub(r'\s*<prop id="efficiency:%s(-sweeps)?" value="[^"]*"/>' % re.escape(method), "", xml)


def with_efficiency(xml, key, e):
    xml = re.sub(r'\s*<prop id="efficiency:%s" value="[^"]*"/>' % re.escape(key), "", xml)
    prop = '<prop id="memory_bandwidth"'
    at = xml.find(prop)
    if at < 0:
        raise Error("the platform has no memory_bandwidth property to place the efficiency beside")
    indent = xml[xml.rfind("\n", 0, at) + 1:at]
    return xml[:at] + f'<prop id="efficiency:{key}" value="{e:.6g}"/>\n' + indent + xml[at:]


def simulate(sim_bin_dir, platform_xml, opts, work):
    platform = os.path.join(work, "platform.xml")
    with open(platform, "w") as f:
        f.write(platform_xml)
    out = os.path.join(work, "one.csv")
    if os.path.exists(out):
        os.remove(out)
    cmd = ["bash", os.path.join(HERE, "run.sh"), platform, "1", "1", os.path.join(sim_bin_dir, "weak_scaling"),
           *opts, "--csv", out]
    r = subprocess.run(cmd, cwd=work, capture_output=True, text=True)
    if r.returncode != 0:
        raise Error("simulation failed: " + " ".join(cmd) + "\n" + r.stdout + r.stderr)
    with open(out, newline="") as f:
        return float(list(csv.DictReader(f))[-1]["elapsed_s"])


def at_unit_efficiency(sim_bin_dir, xml, method, opts, work):
    """(R, S): the simulated time of the run at e = 1, less and of its sweeps.  The sweeps'
    part is what halving their efficiency adds (the CSV's full digits, not the report's)."""
    bare = without_efficiency(xml, method)
    whole = simulate(sim_bin_dir, bare, opts, work)
    sweeps = simulate(sim_bin_dir, with_efficiency(bare, method + "-sweeps", 0.5), opts, work) - whole
    return whole - sweeps, sweeps


def fit_two(points):
    """e and e_sweeps from [(R, S, T), (R, S, T)]: T = R / e + S / e_sweeps at both."""
    (r1, s1, t1), (r2, s2, t2) = points
    det = r1 * s2 - r2 * s1
    if det == 0:
        raise Error("the two SOR points give the same split of rest and sweeps: no fit")
    inv_e, inv_s = (t1 * s2 - t2 * s1) / det, (r1 * t2 - r2 * t1) / det
    if inv_e <= 0 or inv_s <= 0:
        raise Error(f"the SOR points need a non-positive efficiency (1/e = {inv_e:.4g}, 1/e_sweeps = {inv_s:.4g}): "
                    "the model cannot reach both reference times")
    return 1 / inv_e, 1 / inv_s


def main(argv=None):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0])
    ap.add_argument("--platform", required=True)
    ap.add_argument("--sim-bin-dir", required=True)
    ap.add_argument("--reference", required=True, help="'paper' or a measured weak-scaling CSV")
    ap.add_argument("--write", action="store_true", help="write the efficiencies into the platform file")
    args = ap.parse_args(argv)
    args.sim_bin_dir = os.path.abspath(args.sim_bin_dir)
    try:
        with open(args.platform) as f:
            xml = f.read()
        points = paper_points() if args.reference == "paper" else measured_points(args.reference)
        fitted = xml
        with tempfile.TemporaryDirectory(prefix="efsi-calibrate-") as work:
            for method in dict.fromkeys(p[0] for p in points):
                mine = [p for p in points if p[0] == method]
                fitted = without_efficiency(fitted, method)
                runs = []
                for _, opts, seconds in mine:
                    rest, sweeps = at_unit_efficiency(args.sim_bin_dir, xml, method, opts, work)
                    runs.append((rest, sweeps, seconds))
                    print(f"{method}: {' '.join(opts)}: reference {seconds:.4g} s, simulated at e = 1 "
                          f"{rest + sweeps:.4g} s (sweeps {sweeps:.4g} s)")
                if len(mine) == 2:
                    e, e_sweeps = fit_two(runs)
                    fitted = with_efficiency(with_efficiency(fitted, method, e), method + "-sweeps", e_sweeps)
                    print(f"{method}: efficiency {e:.4g}, of its sweeps {e_sweeps:.4g}")
                else:
                    e = (runs[0][0] + runs[0][1]) / runs[0][2]
                    fitted = with_efficiency(fitted, method, e)
                    print(f"{method}: efficiency {e:.4g}")
        if args.write:
            with open(args.platform, "w") as f:
                f.write(fitted)
            print(f"wrote the efficiencies into {args.platform}")
    except (Error, OSError) as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
