#!/usr/bin/python3
"""Tests of plots/make_plots.py on the committed driver outputs in tests/tools/data/.

data/weak-mini.csv and data/strong-mini.csv are rows written by weak_scaling and
strong_scaling (campaign.py local, 1 and 2 ranks, 2 steps, two repeats of every point);
data/accuracy/ is the output of `accuracy --cells 48 --t-end 1 --every 100` (see
data/README.md).  Checked: every figure (PNG and PDF) and both Markdown tables are written;
the tables give the median of the repeats and T_first/T_M of the same configuration,
recomputed here from the CSV; the paper's Tables 2 and 4 are listed beside ours; rows with
valid != 1 are skipped and said so; particles are followed across outputs; bad input gives
one line and exit status 2.
"""

import collections
import math
import csv
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
PLOTS = os.path.join(REPO, "plots", "make_plots.py")
REDUCE = os.path.join(REPO, "plots", "reduce_snapshots.py")
DATA = os.path.join(HERE, "data")
WEAK = os.path.join(DATA, "weak-mini.csv")
STRONG = os.path.join(DATA, "strong-mini.csv")
ACCURACY = os.path.join(DATA, "accuracy")
FIGURES = ("fig2_energy_budget", "fig3_weak_efficiency", "fig4_comm_fraction", "fig5_strong_speedup",
           "particle_trajectories")

sys.path.insert(0, os.path.join(REPO, "plots"))
import snapshots  # noqa: E402
import trajectories  # noqa: E402


def make_plots(*args):
    return subprocess.run([sys.executable, PLOTS, *args], capture_output=True, text=True, timeout=240)


def expected_cells(path):
    """(method, comm, eps) -> {ranks: 'T s (ratio' } recomputed from the CSV: median of valid rows."""
    times = collections.defaultdict(lambda: collections.defaultdict(list))
    with open(path) as f:
        for row in csv.DictReader(f):
            if row["valid"] == "1":
                eps = "%g" % float(row["eps"]) if row["eps"] else ""
                times[(row["method"], row["comm"], eps)][int(row["ranks"])].append(float(row["elapsed_s"]))
    out = {}
    for key, by_ranks in times.items():
        first = statistics.median(by_ranks[min(by_ranks)])
        out[key] = {r: (statistics.median(t), len(t), first / statistics.median(t)) for r, t in by_ranks.items()}
    return out


def eps_text(eps):
    """'0.001' -> '1e-3', as the tables write a tolerance."""
    return ("%g" % float(eps)).replace("0.001", "1e-3").replace("0.0001", "1e-4") if eps else ""


def section(text, title_start):
    """The Markdown between a '## title' line and the next '## '."""
    m = re.search(rf"(?ms)^## {re.escape(title_start)}.*?(?=^## |\Z)", text)
    assert m, title_start
    return m.group(0)


class Figures(unittest.TestCase):
    weak, strong, accuracy = WEAK, STRONG, ACCURACY

    @classmethod
    def setUpClass(cls):
        cls.out = tempfile.mkdtemp(prefix="efsi-plots-")
        cls.r = make_plots("--csv", cls.weak, "--csv", cls.strong, "--accuracy-dir", cls.accuracy, "--box", "7.2",
                           "--out", cls.out)

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.out, True)

    def read(self, name):
        with open(os.path.join(self.out, name)) as f:
            return f.read()

    def test_every_figure_is_written(self):
        self.assertEqual(self.r.returncode, 0, self.r.stdout + self.r.stderr)
        for name in FIGURES:
            for ext, magic in (("png", b"\x89PNG\r\n\x1a\n"), ("pdf", b"%PDF")):
                path = os.path.join(self.out, f"{name}.{ext}")
                self.assertTrue(os.path.isfile(path), path)
                with open(path, "rb") as f:
                    self.assertEqual(f.read(len(magic)), magic, path)
                self.assertGreater(os.path.getsize(path), 10000, path)
        for name in ("table2_weak.md", "table4_strong.md"):
            self.assertTrue(os.path.isfile(os.path.join(self.out, name)))
        self.assertNotIn("skipped", self.r.stdout)

    def check_table(self, name, csv_path, first_title):
        text = self.read(name)
        ours = section(text, "This benchmark")
        expected = expected_cells(csv_path)
        self.assertTrue(expected)
        for (method, comm, eps), by_ranks in expected.items():
            label = method.upper() + f" {comm}"
            if eps:
                label += f" eps={eps_text(eps)}"
            header = next(l for l in ours.splitlines() if l.startswith("| ranks"))
            columns = [c.strip() for c in header.strip("|").split("|")]
            # A set-up that differs between series (steps, block) follows the label in brackets.
            col = next(i for i, c in enumerate(columns) if c == label or c.startswith(label + " ("))
            for ranks, (median, runs, ratio) in by_ranks.items():
                row = next(l for l in ours.splitlines() if l.startswith(f"| {ranks:,} |"))
                cell = [c.strip() for c in row.strip("|").split("|")][col]
                want = f"{median:.4g} s ({ratio:.3f}" + (f", median of {runs})" if runs > 1 else ")")
                self.assertEqual(cell, want, f"{name} {label} ranks {ranks}")
        return text

    def test_table2_medians_and_efficiency_beside_the_paper(self):
        text = self.check_table("table2_weak.md", self.weak, "This benchmark")
        paper = section(text, "Paper, Table 2")
        # ACM: T_1 = 21.57 s, T_8192 = 31.96 s -> 0.675; SOR sync 1e-4 at 8192: 26.81/102.20.
        self.assertRegex(paper, r"\| 1 \| 24.94 s \(1.000\) \| 24.3 s \(1.000\) \|")
        self.assertIn("31.96 s (0.675)", paper)
        self.assertIn("102.2 s (0.262)", paper)
        self.assertEqual(len([l for l in paper.splitlines() if re.match(r"\| [\d,]+ \|", l)]), 14)

    def test_table2_lists_the_iterations_per_step(self):
        ours = section(self.read("table2_weak.md"), "This benchmark")
        want = collections.defaultdict(dict)
        with open(self.weak) as f:
            for row in csv.DictReader(f):
                if row["valid"] == "1" and row["pressure_iterations"]:
                    eps = eps_text(row["eps"])
                    label = f"{row['method'].upper()} {row['comm']}" + (f" eps={eps}" if eps else "")
                    want[label].setdefault(int(row["ranks"]), []).append(float(row["pressure_iterations"]))
        self.assertIn("MG sync eps=1e-3", want, "the data hold the multigrid's rows")
        for label, by_ranks in want.items():
            line = next(l for l in ours.splitlines() if l.startswith(f"- {label}"))
            per = ", ".join(f"{statistics.median(v):g} ({r:,})" for r, v in sorted(by_ranks.items()))
            self.assertTrue(line.endswith(": " + per), line)

    def test_table4_speedup_beside_the_paper(self):
        text = self.check_table("table4_strong.md", self.strong, "This benchmark")
        paper = section(text, "Paper, Table 4")
        self.assertIn("210.9 s (1.000)", paper)
        self.assertIn("31.96 s (6.598)", paper)  # the paper's 82 % efficiency at 8192 cores
        self.assertEqual(len([l for l in paper.splitlines() if re.match(r"\| [\d,]+ \|", l)]), 4)


class CommittedCampaign(Figures):
    """The same checks on the campaign committed in results/campaign/ (results/README.md)."""
    weak = os.path.join(REPO, "results", "campaign", "weak.csv")
    strong = os.path.join(REPO, "results", "campaign", "strong.csv")
    accuracy = os.path.join(REPO, "results", "campaign", "accuracy")


class SkippedRows(unittest.TestCase):
    def test_predicted_rows_are_their_own_series(self):
        # The simulation build's rows (simulated = the platform) never join the measured ones.
        sys.path.insert(0, os.path.join(REPO, "plots"))
        import results_data as rd
        with open(WEAK) as f:
            rows = [r for r in csv.DictReader(f) if r["valid"] == "1"]
        predicted = [dict(r, simulated="ricc", host="node-0") for r in rows]
        loaded = rd.Loaded(rows + predicted, collections.Counter())
        hosts = {s.setup.host for s in rd.series(loaded, "weak")}
        self.assertIn("predicted on ricc", hosts)
        self.assertEqual(len(hosts), 2, hosts)

    def test_invalid_rows_are_left_out_and_reported(self):
        tmp = tempfile.mkdtemp(prefix="efsi-plots-skip-")
        self.addCleanup(shutil.rmtree, tmp, True)
        with open(WEAK) as f:
            rows = list(csv.DictReader(f))
            fields = list(rows[0].keys())
        # The driver's own row, marked as a run whose checks failed.
        rows[0]["valid"] = "0"
        marked = os.path.join(tmp, "weak-marked.csv")
        with open(marked, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=fields)
            w.writeheader()
            w.writerows(rows)
        r = make_plots("--csv", marked, "--out", os.path.join(tmp, "out"))
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("skipped 1 rows with valid != 1", r.stdout)
        with open(os.path.join(tmp, "out", "table2_weak.md")) as f:
            text = f.read()
        self.assertIn("Skipped: 1 rows with valid != 1.", text)
        # The point of the skipped row now rests on the other repeat alone.
        first = rows[0]
        others = [x for x in rows[1:] if (x["method"], x["comm"], x["eps"], x["ranks"]) ==
                  (first["method"], first["comm"], first["eps"], first["ranks"])]
        self.assertEqual(len(others), 1)
        self.assertIn(f"{float(others[0]['elapsed_s']):.4g} s (", text)
        for ext in ("png", "pdf"):
            self.assertTrue(os.path.isfile(os.path.join(tmp, "out", f"fig3_weak_efficiency.{ext}")))


class Trajectories(unittest.TestCase):
    def test_every_particle_is_followed_through_every_output(self):
        for method in ("acm", "fft"):
            path = os.path.join(ACCURACY, f"centroids-{method}.csv")
            with open(path) as f:
                rows = list(csv.DictReader(f))
            steps = sorted({int(r["step"]) for r in rows})
            at_start = sum(1 for r in rows if int(r["step"]) == steps[0])
            tracks = trajectories.track(path, (7.2, 7.2, 7.2))
            self.assertEqual(len(tracks), at_start, method)
            for t in tracks:
                self.assertEqual(len(t["time"]), len(steps), method)
                # Carried downstream by the flow: x (unwrapped) does not go back.
                self.assertGreaterEqual(t["x"][-1], t["x"][0] - 1e-9, method)
        acm = trajectories.track(os.path.join(ACCURACY, "centroids-acm.csv"), (7.2,) * 3)
        fft = trajectories.track(os.path.join(ACCURACY, "centroids-fft.csv"), (7.2,) * 3)
        pairs = trajectories.pair_tracks(fft, acm, (7.2,) * 3)
        self.assertEqual(sorted(pairs), list(range(len(acm))))


def write_state(path, step, time, centre, cells=24, length=7.2, radii=(1.5, 1.5, 1.5)):
    """A state file as the drivers write it (global datasets [z, y, x], step, time, cells and
    lengths as attributes) holding one smooth ellipsoid (by default a ball of radius 1.5) at
    `centre` in phi, periodic in x and z."""
    import h5py
    import numpy as np
    h = length / cells
    c = (np.arange(cells) + 0.5) * h
    z, y, x = np.meshgrid(c, c, c, indexing="ij")
    dx = (x - centre[0] + length / 2) % length - length / 2
    dz = (z - centre[2] + length / 2) % length - length / 2
    # The ellipsoid's level sets scaled to its mean radius: the interface about a cell wide.
    rho = np.sqrt((dx / radii[0]) ** 2 + ((y - centre[1]) / radii[1]) ** 2 + (dz / radii[2]) ** 2)
    r = rho * (radii[0] * radii[1] * radii[2]) ** (1 / 3)
    with h5py.File(path, "w") as f:
        f["phi"] = 0.5 * (1 - np.tanh((r - (radii[0] * radii[1] * radii[2]) ** (1 / 3)) / h))
        f["u"] = np.zeros((cells, cells, cells))
        f.attrs["step"] = step
        f.attrs["time"] = time
        for a in "xyz":
            f.attrs["cells_" + a] = cells
            f.attrs["length_" + a] = length


class ParticleSurfaces(unittest.TestCase):
    """fig1_particle_surfaces and accuracy_comparison.md from HDF5 snapshots: two methods whose
    ball is the same at t = 0 and 5 and one cell apart in x at t = 20."""

    def test_surfaces_and_the_comparison(self):
        tmp = tempfile.mkdtemp(prefix="efsi-plots-h5-")
        self.addCleanup(shutil.rmtree, tmp, True)
        acc = os.path.join(tmp, "accuracy")
        shutil.copytree(ACCURACY, acc)
        h = 7.2 / 24
        for method, shift in (("acm", h), ("fft", 0.0)):
            write_state(os.path.join(acc, f"snapshot-{method}-00000000.h5"), 0, 0.0, (3.6, 3.6, 3.6))
            write_state(os.path.join(acc, f"snapshot-{method}-00010000.h5"), 10000, 5.0, (3.6, 3.6, 3.6))
            write_state(os.path.join(acc, f"fields-{method}.h5"), 40000, 20.0, (3.6 + shift, 3.6, 3.6))
        out = os.path.join(tmp, "out")
        r = make_plots("--accuracy-dir", acc, "--out", out, "--formats", "png")
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        with open(os.path.join(out, "fig1_particle_surfaces.png"), "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        with open(os.path.join(out, "accuracy_comparison.md")) as f:
            text = f.read()
        rows = {}
        for line in section(text, "phi and the solid").splitlines():
            cells = [c.strip() for c in line.strip("|").split("|")]
            if len(cells) == 6 and cells[0][0].isdigit():
                rows[float(cells[0])] = [float(v) for v in cells[1:]]
        self.assertEqual(sorted(rows), [0.0, 5.0, 20.0])
        for t in (0.0, 5.0):
            self.assertEqual(rows[t][0], 0.0, "identical states")
            self.assertEqual(rows[t][3], 0.0)
        # A ball of radius R moved by h: the two sides it gains and loses, 2 pi R^2 h, against
        # its 4/3 pi R^3: 3 h / (2 R) = 0.3.
        max_diff, _, solid, mismatch, share = rows[20.0]
        self.assertAlmostEqual(solid, 4 / 3 * 3.14159 * 1.5 ** 3, delta=0.15 * solid)
        self.assertGreater(max_diff, 0.3)
        self.assertAlmostEqual(share, 0.3, delta=0.05)
        self.assertIn("## Centroids at the last common output", text)
        # The same ball one cell along: the shape table pairs the two, one cell apart, with
        # the same volume and semi-axes (those of the ball, to within its voxels).
        shapes = [[c.strip() for c in line.strip("|").split("|")]
                  for line in section(text, "Particle shapes at t = 20").splitlines() if line.startswith("| 0 |")]
        self.assertEqual(len(shapes), 1, text)
        _, distance, volume, dvolume, semi, dsemi = shapes[0]
        self.assertAlmostEqual(float(distance), h, delta=1e-9)
        self.assertAlmostEqual(float(dvolume), 0.0, delta=1e-12)
        for v in semi.split(","):
            self.assertAlmostEqual(float(v), 1.5, delta=0.05 * 1.5)
        for v in dsemi.split(","):
            self.assertAlmostEqual(float(v), 0.0, delta=1e-9)


class ParticleShapes(unittest.TestCase):
    """snapshots.particle_shapes: an ellipsoid's semi-axes, largest first, and one particle
    across the periodic sides, its centroid in the box."""

    def shapes(self, centre, radii):
        tmp = tempfile.mkdtemp(prefix="efsi-plots-shape-")
        self.addCleanup(shutil.rmtree, tmp, True)
        path = os.path.join(tmp, "s.h5")
        write_state(path, 0, 0.0, centre, cells=72, radii=radii)
        return snapshots.particle_shapes(snapshots.Snapshot(path))

    def test_ellipsoid_semi_axes(self):
        (one,) = self.shapes((3.6, 3.6, 3.6), (1.2, 0.6, 2.0))
        for got, want in zip(one["semi_axes"], (2.0, 1.2, 0.6)):
            self.assertAlmostEqual(got, want, delta=0.03 * want)
        self.assertAlmostEqual(one["volume"], 4 / 3 * math.pi * 2.0 * 1.2 * 0.6, delta=0.03 * one["volume"])
        for got, want in zip(one["centroid"], (3.6, 3.6, 3.6)):
            self.assertAlmostEqual(got, want, delta=1e-9)

    def test_across_the_periodic_sides(self):
        whole = self.shapes((3.6, 3.6, 3.6), (1.5, 1.0, 1.2))
        split = self.shapes((7.0, 3.6, 0.3), (1.5, 1.0, 1.2))
        self.assertEqual(len(split), 1, "one particle across the x and z sides, not four")
        self.assertAlmostEqual(split[0]["volume"], whole[0]["volume"], delta=1e-12)
        for got, want in zip(split[0]["semi_axes"], whole[0]["semi_axes"]):
            self.assertAlmostEqual(got, want, delta=1e-9)
        for got, want in zip(split[0]["centroid"], (7.0, 3.6, 0.3)):
            self.assertAlmostEqual(got, want, delta=1e-9)


class PhiOnlySnapshots(unittest.TestCase):
    """reduce_snapshots.py keeps phi bit for bit with the attributes, and make_plots.py draws
    the same figure and comparison from an accuracy directory's phi/ folder as from the full
    state files."""

    def setUp(self):
        import h5py
        self.tmp = tempfile.mkdtemp(prefix="efsi-plots-phi-")
        self.addCleanup(shutil.rmtree, self.tmp, True)
        self.full = os.path.join(self.tmp, "full")
        shutil.copytree(ACCURACY, self.full)
        h = 7.2 / 24
        self.files = []
        for method, shift in (("acm", h), ("fft", 0.0)):
            for step, time, x in ((0, 0.0, 3.6), (10000, 5.0, 3.6), (40000, 20.0, 3.6 + shift)):
                path = os.path.join(self.full, f"snapshot-{method}-{step:08d}.h5")
                write_state(path, step, time, (x, 3.6, 3.6))
                with h5py.File(path, "a") as f:
                    f.attrs["stagger_phi"], f.attrs["stagger_u"] = "cell", "face_x"
                self.files.append(path)

    def reduce(self, *args):
        return subprocess.run([sys.executable, REDUCE, *args], capture_output=True, text=True, timeout=120)

    def test_phi_kept_bitwise_and_drawn_alike(self):
        import h5py
        acc = os.path.join(self.tmp, "reduced")
        shutil.copytree(ACCURACY, acc)
        os.mkdir(os.path.join(acc, "phi"))
        r = self.reduce("--out", os.path.join(acc, "phi"), *self.files)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        for path in self.files:
            with h5py.File(path) as a, h5py.File(os.path.join(acc, "phi", os.path.basename(path))) as b:
                self.assertEqual(sorted(b.keys()), ["phi"])
                self.assertEqual(a["phi"][...].tobytes(), b["phi"][...].tobytes())
                self.assertEqual(b["phi"].compression, "gzip")
                kept = {k: a.attrs[k] for k in a.attrs if k != "stagger_u"}
                self.assertEqual(kept, {k: b.attrs[k] for k in b.attrs})
                self.assertIn("stagger_phi", kept)
        self.assertFalse([f for f in os.listdir(os.path.join(acc, "phi")) if not f.endswith(".h5")])
        tables = {}
        for name, directory in (("full", self.full), ("reduced", acc)):
            out = os.path.join(self.tmp, "out-" + name)
            r = make_plots("--accuracy-dir", directory, "--out", out, "--formats", "png", "--box", "7.2")
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            self.assertTrue(os.path.isfile(os.path.join(out, "fig1_particle_surfaces.png")), r.stdout)
            with open(os.path.join(out, "accuracy_comparison.md")) as f:
                tables[name] = section(f.read(), "phi and the solid")
        self.assertIn("| 20 |", tables["full"])
        self.assertEqual(tables["full"], tables["reduced"])

    def test_single_and_zeroed(self):
        import h5py
        import numpy as np
        out = os.path.join(self.tmp, "small")
        os.mkdir(out)
        r = self.reduce("--out", out, "--single", "--zero-below", "1e-3", self.files[2])
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        with h5py.File(self.files[2]) as a, h5py.File(os.path.join(out, os.path.basename(self.files[2]))) as b:
            want = a["phi"][...].astype(np.float32)
            self.assertGreater(((want > 0) & (want < 1e-3)).sum(), 0, "the ball has tails to cut")
            want[np.abs(want) < 1e-3] = 0
            self.assertEqual(b["phi"].dtype, np.float32)
            self.assertEqual(want.tobytes(), b["phi"][...].tobytes())
            self.assertEqual(b.attrs["phi_reduced"], "rounded to float32, |phi| < 0.001 set to 0")
            self.assertEqual(int(b.attrs["step"]), 40000)

    def test_errors_one_line(self):
        import h5py
        no_phi = os.path.join(self.tmp, "no-phi.h5")
        with h5py.File(no_phi, "w") as f:
            f["u"] = [1.0]
        out = os.path.join(self.tmp, "out")
        os.mkdir(out)
        cases = [
            (["--out", os.path.join(self.tmp, "missing"), self.files[0]], 2, "not an existing directory"),
            (["--out", out, os.path.join(self.tmp, "missing.h5")], 2, "missing.h5"),
            (["--out", out, "--zero-below", "0.7", self.files[0]], 2, "--zero-below 0.7 is outside [0, 0.5)"),
            (["--out", out, "--zero-below", "nan", self.files[0]], 2, "--zero-below nan"),
            (["--out", out, no_phi], 1, "no phi dataset"),
            (["--out", self.full, self.files[0]], 1, "would overwrite its own source"),
            (["--out", "/proc", self.files[0]], 1, "/proc/snapshot-acm-00000000.h5"),
        ]
        for args, status, needle in cases:
            with self.subTest(args=args):
                r = self.reduce(*args)
                self.assertEqual(r.returncode, status, r.stdout + r.stderr)
                lines = r.stderr.splitlines()
                self.assertEqual(len(lines), 1, r.stderr)
                self.assertTrue(lines[0].startswith("reduce_snapshots.py: error: "), lines[0])
                self.assertIn(needle, lines[0])
        self.assertEqual(os.listdir(out), [])


class Errors(unittest.TestCase):
    def test_one_line_and_status_2(self):
        tmp = tempfile.mkdtemp(prefix="efsi-plots-bad-")
        self.addCleanup(shutil.rmtree, tmp, True)
        out = os.path.join(tmp, "out")
        cases = [
            ([], "give at least one --csv"),
            (["--csv", os.path.join(tmp, "missing.csv")], "missing.csv"),
            (["--csv", os.path.join(ACCURACY, "series-acm.csv")], "not a results CSV"),
            (["--csv", WEAK, "--formats", "gif"], "gif"),
            (["--accuracy-dir", tmp], "series-acm.csv"),
            (["--accuracy-dir", ACCURACY, "--box", "0,1,1"], "0,1,1"),
            (["--csv", WEAK, "--bogus"], "--bogus"),
        ]
        for args, needle in cases:
            with self.subTest(args=args):
                r = make_plots(*args, "--out", out)
                self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
                lines = r.stderr.splitlines()
                self.assertEqual(len(lines), 1, r.stderr)
                self.assertTrue(lines[0].startswith("make_plots.py: error: "), lines[0])
                self.assertIn(needle, lines[0])
                self.assertFalse(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()
