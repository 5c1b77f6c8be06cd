"""Reading result CSVs (docs/numerics.md, "Output: the CSV run record") and the paper's tables, grouping and reducing them.

Standard library only, so the tests can check the numbers without matplotlib.

Rules (issue 5):
- only rows with valid=1 count; the others are counted and reported, never plotted;
- rows are grouped by configuration (method, comm, eps) and set-up (block per rank or
  global grid, steps, threads, host; a simulated row's host is "predicted on PLATFORM"); repeated runs of one point give the median elapsed
  time (and the median communication fraction);
- weak efficiency T_1/T_M uses T_1 of the same group; strong speedup T_ref/T_M uses the
  group's smallest rank count as the reference.
"""

import collections
import csv
import dataclasses
import math
import os
import statistics
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "harness"))
from paper_tables import blocking_label, eps_label  # noqa: E402,F401  (one spelling of each)

REQUIRED = ("experiment", "method", "comm", "eps", "ranks", "threads", "px", "py", "pz", "nx", "ny", "nz",
            "steps", "elapsed_s", "comm_fraction", "valid", "host")


class DataError(ValueError):
    pass


@dataclasses.dataclass(frozen=True, order=True)
class Config:
    method: str
    comm: str
    eps: str
    blocking: str = ""  # SOR's sweeps between exchanges; "" for the paper's pattern (1)

    @property
    def label(self):
        eps = f" eps={self.eps}" if self.eps else ""
        blocking = f" K={self.blocking}" if self.blocking else ""
        return f"{self.method.upper()} {self.comm}{eps}{blocking}"

    @property
    def sort_key(self):
        # By method, then tolerance; sync before async, as in the paper's columns; the
        # blocked series after the paper's pattern.
        return (self.method, self.eps, self.blocking, self.comm != "sync", self.comm)


@dataclasses.dataclass(frozen=True, order=True)
class Setup:
    block: str     # "64x64x64/rank" (weak) or "128x64x64" (strong, whole grid)
    steps: int
    threads: int
    host: str

    def describe(self, fields):
        parts = {"block": self.block, "steps": f"{self.steps} steps", "threads": f"{self.threads} thread(s)/rank",
                 "host": self.host}
        return ", ".join(parts[f] for f in fields)


@dataclasses.dataclass
class Point:
    ranks: int
    elapsed_s: float        # median over the runs
    comm_fraction: float    # median over the runs
    runs: int
    iterations: float = None  # median pressure iterations per step (SOR sweeps, V-cycles); None: none


@dataclasses.dataclass
class Series:
    experiment: str
    config: Config
    setup: Setup
    points: list            # of Point, by ranks

    def reference(self):
        return self.points[0]

    def ratio(self):
        """Weak: T_1/T_M (T at the smallest rank count, which is 1 in a full sweep).
        Strong: T_ref/T_M.  Both are T_first / T_M."""
        t0 = self.points[0].elapsed_s
        return [t0 / p.elapsed_s for p in self.points]


@dataclasses.dataclass
class Loaded:
    rows: list
    skipped: collections.Counter   # reason -> count

    def skipped_text(self):
        return "; ".join(f"{n} {why}" for why, n in sorted(self.skipped.items()))


def read_rows(paths):
    """Rows of every CSV (header from each file), with the skipped ones counted by reason."""
    rows, skipped = [], collections.Counter()
    for path in paths:
        with open(path, newline="") as f:
            reader = csv.DictReader(f)
            missing = [c for c in REQUIRED if c not in (reader.fieldnames or [])]
            if missing:
                raise DataError(f"{path}: not a results CSV (missing columns {', '.join(missing)})")
            for row in reader:
                if row.get("valid") != "1":
                    skipped["rows with valid != 1"] += 1
                    continue
                try:
                    elapsed = float(row["elapsed_s"])
                    ok = math.isfinite(elapsed) and elapsed > 0
                except ValueError:
                    ok = False
                if not ok:
                    skipped["rows without a positive elapsed_s"] += 1
                    continue
                rows.append(row)
    return Loaded(rows, skipped)


def config_of(row):
    # A method that stops on a tolerance fills the eps column; the others leave it empty.
    return Config(row["method"], row["comm"], eps_label(row["eps"]), blocking_label(row.get("sweeps_per_exchange")))


def setup_of(row, experiment):
    nx, ny, nz = int(row["nx"]), int(row["ny"]), int(row["nz"])
    if experiment == "weak":
        px, py, pz = int(row["px"]), int(row["py"]), int(row["pz"])
        block = f"{nx // px}x{ny // py}x{nz // pz}/rank"
    else:
        block = f"{nx}x{ny}x{nz}"
    # A simulated row's host is a platform node; the platform names the series, so that a
    # prediction stands beside the measurements of the same configuration, never among them.
    host = f"predicted on {row['simulated']}" if (row.get("simulated") or "").strip() else row["host"]
    return Setup(block, int(row["steps"]), int(row["threads"]), host)


def series(loaded, experiment):
    """The experiment's rows grouped into Series, sorted by method, tolerance and halo mode."""
    groups = collections.defaultdict(lambda: collections.defaultdict(list))
    for row in loaded.rows:
        if row["experiment"] != experiment:
            continue
        key = (config_of(row), setup_of(row, experiment))
        groups[key][int(row["ranks"])].append(row)
    out = []
    for (config, setup), by_ranks in groups.items():
        pts = []
        for ranks in sorted(by_ranks):
            rs = by_ranks[ranks]
            its = [float(r["pressure_iterations"]) for r in rs if (r.get("pressure_iterations") or "").strip()]
            pts.append(Point(ranks, statistics.median(float(r["elapsed_s"]) for r in rs),
                             statistics.median(float(r["comm_fraction"]) for r in rs), len(rs),
                             statistics.median(its) if its else None))
        out.append(Series(experiment, config, setup, pts))
    out.sort(key=lambda s: (s.config.sort_key, s.setup))
    return out


def varying_setup_fields(all_series):
    """The set-up fields that differ between series (so labels name only those)."""
    fields = []
    for f in ("block", "steps", "threads", "host"):
        if len({getattr(s.setup, f) for s in all_series}) > 1:
            fields.append(f)
    return fields


def label(s, fields):
    extra = s.setup.describe(fields)
    return f"{s.config.label} ({extra})" if extra else s.config.label


# --- the paper ---------------------------------------------------------------------------------

def paper_series(path, table):
    """Series of the paper's Table 2 (weak) or 4 (strong): elapsed times against cores."""
    experiment = {"2": "weak", "4": "strong"}[str(table)]
    by_config = collections.defaultdict(list)
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            if row["table"] != str(table):
                continue
            config = config_of(row)
            by_config[config].append(Point(int(row["cores"]), float(row["elapsed_s"]), math.nan, 1))
    if not by_config:
        raise DataError(f"{path}: no rows of table {table}")
    setup = Setup("64x64x64/rank" if experiment == "weak" else "2048x1024x1024", 0, 1, "RICC")
    # In the order of the paper's columns, as its table lists them.
    return [Series(experiment, c, setup, sorted(p, key=lambda q: q.ranks)) for c, p in by_config.items()]


# --- accuracy-run series -------------------------------------------------------------------------

def read_numeric_csv(path):
    """Columns of a numeric CSV as lists of floats (the accuracy driver's series/centroids)."""
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        cols = {name: [] for name in reader.fieldnames or []}
        for row in reader:
            for name in cols:
                cols[name].append(float(row[name]))
    if not cols or not next(iter(cols.values())):
        raise DataError(f"{path}: no rows")
    return cols
