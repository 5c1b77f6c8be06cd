"""ReFrame checks of the EFSI-Bench drivers: one per driver and pressure method.

Each check runs a small case of its driver on `ranks` MPI ranks (2) with `threads` OpenMP
threads (1) and
- is sane when the driver prints its validation line ending in PASSED, its banner names
  the method and the rank count, and its CSV row (run.csv) is one valid, not oversubscribed
  row of that method, rank and thread count;
- reports elapsed (slowest rank, measured steps), M cell updates/s and the communication
  fraction from the driver's timing report.
References per system and partition come from ../references/SYSTEM.json (dev-2core: this
development machine); elsewhere the figures are reported without one.  `accuracy` has no
SOR path (it compares ACM with the FFT reference), so there are eleven checks.

Variables (-S NAME=VALUE): bin_dir (default $EFSI_BIN_DIR or build/bin of this checkout),
ranks, threads, use_references (false: no reference, the figures are only reported).
"""

import csv
import json
import os

import reframe as rfm
import reframe.utility.sanity as sn
import reframe.utility.typecheck as typ
from reframe.core.builtins import parameter, performance_function, run_after, run_before, sanity_function, variable

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
REFERENCES = os.path.join(os.path.dirname(HERE), "references")

# Small cases: seconds each on two cores, still the driver's own validation.
CASE_OPTIONS = {
    "channel": ["--cells", "32", "--length", "3.6", "--steps", "5"],
    "weak_scaling": ["--steps", "2"],
    "strong_scaling": ["--scale", "16", "--steps", "2"],
    "accuracy": ["--cells", "32", "--length", "3.6", "--t-end", "0.01", "--out", "."],
}
CASES = [(d, m) for d in CASE_OPTIONS for m in ("acm", "sor", "fft") if (d, m) != ("accuracy", "sor")]

# Loose on purpose: the machines are shared and noisy, sanity is the hard check.  Slower than
# twice the reference or under half its rate fails; faster never does.
BOUNDS = {"elapsed": (None, 1.0), "mlups": (-0.5, None), "comm_fraction": (None, None)}
UNITS = {"elapsed": "s", "mlups": "Mcell/s", "comm_fraction": ""}


def load_references(case):
    """{'system:partition': {var: (value, lower, upper, unit)}} from every references/*.json."""
    out = {}
    for name in sorted(os.listdir(REFERENCES)):
        if not name.endswith(".json"):
            continue
        with open(os.path.join(REFERENCES, name)) as f:
            data = json.load(f)
        for target, cases in data.get("references", {}).items():
            values = cases.get(case, {})
            out[target] = {v: (values[v], *BOUNDS[v], UNITS[v]) for v in BOUNDS if v in values}
    return out


@sn.deferrable
def csv_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


@rfm.simple_test
class EfsiDriverCheck(rfm.RunOnlyRegressionTest):
    case = parameter(CASES, fmt=lambda c: f"{c[0]}-{c[1]}")
    bin_dir = variable(str, value=os.environ.get("EFSI_BIN_DIR", os.path.join(REPO, "build", "bin")))
    ranks = variable(int, value=2)
    threads = variable(int, value=1)
    # false: report the figures without judging them (the CTest run on a loaded machine).
    use_references = variable(typ.Bool, value=True)  # bool would take "false" as true
    valid_systems = ["*"]
    valid_prog_environs = ["*"]
    time_limit = "10m"
    maintainers = ["EFSI-Bench"]
    tags = {"efsi"}

    @run_after("init")
    def set_up(self):
        self.driver, self.method = self.case
        self.descr = f"{self.driver} with {self.method}, small case"
        self.tags |= {self.driver, self.method}
        if self.use_references:
            self.reference = load_references(f"{self.driver}-{self.method}")

    @run_before("run")
    def set_command(self):
        self.num_tasks = self.ranks
        self.num_cpus_per_task = self.threads
        self.executable = os.path.join(self.bin_dir, self.driver)
        method = ["--methods" if self.driver == "accuracy" else "--method", self.method]
        self.executable_opts = method + CASE_OPTIONS[self.driver] + ["--csv", "run.csv"]
        self.env_vars = {"OMP_NUM_THREADS": str(self.threads), "OMP_PLACES": "cores", "OMP_PROC_BIND": "close"}

    @sanity_function
    def validated(self):
        rows = csv_rows(os.path.join(self.stagedir, "run.csv"))
        row = rows[0]
        return sn.all([
            sn.assert_found(r"^validation: .*: PASSED$", self.stdout),
            sn.assert_found(rf"^{self.driver}: {self.method}, \w+ \w+ halo, {self.ranks} ranks as ", self.stdout),
            sn.assert_eq(sn.len(rows), 1, msg="run.csv holds {0} rows, not {1}"),
            sn.assert_eq(row["method"], self.method),
            sn.assert_eq(row["ranks"], str(self.ranks)),
            sn.assert_eq(row["threads"], str(self.threads)),
            sn.assert_eq(row["oversubscribed"], "0", msg="the run was oversubscribed"),
            sn.assert_eq(row["valid"], "1", msg="the row is not valid"),
        ])

    @performance_function("s")
    def elapsed(self):
        return sn.extractsingle(r"^timing over \d+ steps \(slowest rank (\S+) s,", self.stdout, 1, float)

    @performance_function("Mcell/s")
    def mlups(self):
        return sn.extractsingle(r"^timing over .*, (\S+) Mcell updates/s\)", self.stdout, 1, float)

    @performance_function("")
    def comm_fraction(self):
        return sn.extractsingle(r"^\s*comm fraction (\S+) \(", self.stdout, 1, float)
