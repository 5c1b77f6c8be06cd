#!/usr/bin/env python3
"""64 ranks on a small machine (oversubscribed): the 4 x 4 x 4 rank grid of 8^3 cells each.

The paper's campaigns run thousands of ranks; the other tests stop at 8.  Set-up, memory or
output that grows with the rank count, or a decomposition bug that shows only with four
ranks along every axis, shows here:

- ACM and SOR (async, at the paper's tolerance 1e-3) give the fields of one rank, within the
  decomposition-invariance tolerance of the solver tests (1e-12 of each field's largest
  magnitude), and the same series, centroids and profile to rounding;
- every output file is whole: the checkpoint's global datasets, one CSV row of the 4 x 4 x 4
  grid, as many series, centroid and profile rows as on one rank;
- the run's header line does not list the ranks one by one: it and the CSV's `cores` cell
  stay short (distinct bindings with their counts).

Debian's /usr/bin/python3 with h5py and numpy.  Usage:

    test_many_ranks.py --bin-dir BUILD/bin [unittest options]
"""

import csv

import h5py
import numpy as np

import driver_harness
from driver_harness import *  # noqa: F401,F403 (launching, tables, row checks)

RANKS = 64
GRID = "4,4,4"
BOX = ["--cells", "32", "--length", "3.6"]  # 8^3 cells a rank, the two lattice particles
FIELDS = ("u", "v", "w", "p", "phi", "Bt11", "Bt22", "Bt33", "Bt12", "Bt13", "Bt23")
INVARIANCE = 1e-12  # tests/pressure/acm/test_acm_solver.cpp
ROUNDING = 1e-10    # sums over ranks in another order: the diagnostics, centroids and means
# The series' columns that measure the flow; the others (div_rms, eps_solid, ...) are
# rounding noise around zero at this stage, different in every decomposition.
SERIES_COLUMNS = ("time", "kinetic", "input", "u_max", "flow_rate", "solid_fraction")
HEADER_LIMIT = 200  # characters of the run's first line, whatever the rank count
METHODS = {
    "acm": ["--method", "acm"],
    "sor": ["--method", "sor", "--comm", "async", "--eps", "1e-3", "--dt", "6.25e-5"],
}


def table(path):
    with open(path, newline="") as f:
        text = f.read()
    rows = list(csv.DictReader(text.splitlines()))
    return text, rows


class ManyRanks(DriverTestCase):
    program = "channel"

    def outputs(self, tag):
        return ["--steps", "3", "--every", "1", "--checkpoint", f"{tag}.h5", "--series", f"{tag}-series.csv",
                "--centroids", f"{tag}-centroids.csv", "--profile", f"{tag}-profile.csv", "--csv", f"{tag}-run.csv"]

    def assert_whole(self, tag, ranks, grid):
        with h5py.File(self.path(f"{tag}.h5"), "r") as f:
            fields = {name: f[name][...] for name in FIELDS}
        self.assertEqual(fields["p"].shape, (32, 32, 32))
        self.assertTrue(all(np.isfinite(a).all() for a in fields.values()), tag)
        text, rows = table(self.path(f"{tag}-run.csv"))
        self.assertTrue(text.endswith("\n"), tag)
        self.assertEqual(len(rows), 1, tag)
        r = rows[0]
        self.assertEqual((r["ranks"], r["px"], r["py"], r["pz"]), (str(ranks), *grid), tag)
        self.assertLess(len(r["cores"]), HEADER_LIMIT, r["cores"])
        self.assertEqual(sum(int(b.split("*")[1]) for b in r["cores"].split("/")), ranks, r["cores"])
        _, raw = read_table(self.path(f"{tag}-run.csv"))
        self.check_header(raw[0])
        self.assertEqual(len(raw[1]), len(raw[0]), tag)
        files = {}
        for kind in ("series", "centroids", "profile"):
            text, rows = table(self.path(f"{tag}-{kind}.csv"))
            self.assertTrue(text.endswith("\n"), f"{tag}-{kind}")
            self.assertTrue(all(None not in row and None not in row.values() for row in rows), f"{tag}-{kind}")
            files[kind] = rows
        return fields, files

    def assert_close_rows(self, a, b, columns, what):
        self.assertEqual(len(a), len(b), what)
        for col in columns:
            x = np.array([float(r[col]) for r in a])
            y = np.array([float(r[col]) for r in b])
            scale = max(np.abs(x).max(), 1e-300)
            self.assertLessEqual(np.abs(x - y).max(), ROUNDING * scale, f"{what}: {col}")

    def test_fields_and_outputs_as_on_one_rank(self):
        for name, method in METHODS.items():
            with self.subTest(method=name):
                many = self.run_ok(BOX + method + ["--decomp", GRID] + self.outputs(f"{name}-many"), ranks=RANKS)
                first = many.out.splitlines()[0]
                self.assertIn(f"{RANKS} ranks as 4x4x4, local block 8x8x8", first)
                self.assertLess(len(first), HEADER_LIMIT, first)
                self.run_ok(BOX + method + self.outputs(f"{name}-one"), ranks=1)
                f64, o64 = self.assert_whole(f"{name}-many", RANKS, ("4", "4", "4"))
                f1, o1 = self.assert_whole(f"{name}-one", 1, ("1", "1", "1"))
                for field in FIELDS:
                    scale = max(np.abs(f1[field]).max(), 1e-300)
                    self.assertLessEqual(np.abs(f64[field] - f1[field]).max(), INVARIANCE * scale,
                                         f"{name}: {field} on {RANKS} ranks")
                self.assertEqual(len(o1["series"]), 5)  # step 0, the warm-up, 3 measured
                self.assert_close_rows(o64["series"], o1["series"], SERIES_COLUMNS, f"{name} series")
                self.assertEqual(len(o1["centroids"]), 2 * 5)
                self.assert_close_rows(o64["centroids"], o1["centroids"], ("volume", "x", "y", "z"),
                                       f"{name} centroids")
                self.assertEqual(len(o1["profile"]), 32)
                self.assert_close_rows(o64["profile"], o1["profile"], ("y", "u", "phi"), f"{name} profile")


if __name__ == "__main__":
    driver_harness.main()
