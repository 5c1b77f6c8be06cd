#!/usr/bin/env python3
"""End-to-end tests of the experiment drivers weak_scaling, strong_scaling and accuracy
through their command lines (docs/numerics.md, "Experiments", and docs/architecture.md, "Programs and their command lines"; issue 5).

Rows with exactly the section-8 columns first, numbers where numbers belong, valid = 1 and a
communication fraction in [0, 1], on 1 and 2 ranks; the weak-scaling box growing with the
rank grid; the strong-scaling dry run of 8192 full-size ranks and its memory figure checked
against a real run's resident size; the accuracy outputs (series, centroids, the final fields as parallel HDF5 with XDMF);
bad options: one line, exit status 2, nothing written.

    test_scaling_cli.py --bin-dir BUILD/bin [unittest options]
"""

import os
import re
import subprocess
import sys

import h5py
import numpy as np

import driver_harness
from driver_harness import EXIT_OUTPUT_FAILED, DriverTestCase, read_table, run, snapshot

PAPER_DX = 3.6 / 64


def fields_of(path):
    """Every dataset of a state file (snapshot or final fields) by name."""
    with h5py.File(path, "r") as f:
        return {name: f[name][...] for name in f.keys()}


class WeakScaling(DriverTestCase):
    program = "weak_scaling"

    def test_rows_on_one_and_two_ranks(self):
        # (ranks, arguments, method, comm, steps, dt): the paper's 64^3 block and 2 particles
        # per rank, a few steps of every method.
        runs = [
            (1, ["--steps", "3"], "acm", "sync", 3, 1.25e-5),
            (2, ["--steps", "3", "--comm", "async"], "acm", "async", 3, 1.25e-5),
            (1, ["--method", "sor", "--ns", "30", "--nc", "3", "--steps", "2"], "sor", "sync", 2, 6.25e-5),
            (2, ["--method", "sor", "--comm", "async", "--steps", "2", "--nc", "2"], "sor", "async", 2, 6.25e-5),
            (2, ["--method", "fft", "--steps", "2"], "fft", "sync", 2, 6.25e-5),
            (2, ["--method", "mg", "--eps", "1e-4", "--nc", "2", "--steps", "2"], "mg", "sync", 2, 6.25e-5),
        ]
        for n, (ranks, args, method, comm, steps, dt) in enumerate(runs, start=1):
            with self.subTest(ranks=ranks, args=" ".join(args)):
                self.run_ok(args + ["--csv", "weak.csv"], ranks=ranks)
                _, rows = read_table(self.path("weak.csv"))
                self.assertEqual(len(rows), n + 1)
                header = rows[0]
                self.check_header(header)
                r = dict(zip(header, rows[n]))
                dims = (int(r["px"]), int(r["py"]), int(r["pz"]))
                cells = tuple(64 * p for p in dims)  # the global box is the rank grid times the block
                self.check_row(header, rows[n], ranks, 1, cells, steps, 2 * ranks, comm, dims=dims,
                               experiment="weak", method=method, dt=dt, div_rms_max=1.0)
                if method == "sor":
                    self.assertEqual(r["eps"], "" if "--ns" in args else "0.001")
                    self.assertEqual(r["ns_per_step"], "30" if "--ns" in args else "213")
                if method == "mg":
                    self.assertEqual(r["eps"], "0.0001")
                    self.assertGreater(float(r["pressure_setup_s"]), 0.0)

    def test_paper_defaults_are_announced(self):
        res = self.run_ok(["--steps", "1", "--local", "16", "--particles-per-rank", "0"], ranks=2)
        self.assertRegex(res.out, r"acm, sync direct halo, 2 ranks as 1x2x1, local block 16x16x16")
        self.assertRegex(res.out, r"16x32x16 cells, box 0\.9 x 1\.8 x 0\.9, 0 particles, G=50, dt=1\.25e-05")
        res = self.run_ok(["--steps", "1", "--local", "16", "--particles-per-rank", "0", "--method", "sor"])
        self.assertRegex(res.out, r"dt=6\.25e-05, 1 steps \+ 1 warm-up")
        self.assertRegex(res.out, r"N_S = 213 SOR sweeps per step, N_C = 20 Crank-Nicolson sweeps per step")

    def test_single_rank_mpi_time_is_near_zero(self):
        # One rank: the halo partners are the rank itself and the reductions have one member.
        self.run_ok(["--local", "32", "--particles-per-rank", "0", "--steps", "10", "--csv", "one.csv"])
        _, rows = read_table(self.path("one.csv"))
        v = self.check_row(rows[0], rows[1], 1, 1, (32, 32, 32), 10, 0, "sync", dims=(1, 1, 1),
                           experiment="weak")
        self.assertLess(v["comm_fraction"], 0.05, dict(zip(rows[0], rows[1])))


class StrongScaling(DriverTestCase):
    program = "strong_scaling"

    def test_scaled_rows_on_one_and_two_ranks(self):
        for n, ranks in enumerate((1, 2), start=1):
            with self.subTest(ranks=ranks):
                self.run_ok(["--scale", "16", "--steps", "2", "--csv", "strong.csv"], ranks=ranks)
                _, rows = read_table(self.path("strong.csv"))
                self.check_header(rows[0])
                # 2048 x 1024 x 1024 / 16 with 16384 / 16^3 particles.
                self.check_row(rows[0], rows[n], ranks, 1, (128, 64, 64), 2, 4, "sync", experiment="strong",
                               div_rms_max=1.0)

    def dry_run(self, ranks, *extra):
        res = self.run_ok(["--dry-run", "--ranks", str(ranks)] + list(extra))
        m = re.search(r"memory per rank: ([\d.]+) GiB \((\d+) fields ([\d.]+) GiB", res.out)
        self.assertIsNotNone(m, res.out)
        return res, float(m.group(1)), int(m.group(2)), float(m.group(3))

    def test_dry_run_of_8192_full_size_ranks(self):
        before = snapshot(self.dir)
        res, total, fields, field_gib = self.dry_run(8192)
        self.assertIn("2048x1024x1024 cells", res.out)
        self.assertIn("16384 particles", res.out)
        m = re.search(r"ranks 8192 as (\d+)x(\d+)x(\d+), local block (\d+)x(\d+)x(\d+)", res.out)
        self.assertIsNotNone(m, res.out)
        p, local = [int(x) for x in m.groups()[:3]], [int(x) for x in m.groups()[3:]]
        self.assertEqual(p[0] * p[1] * p[2], 8192)
        self.assertEqual([p[a] * local[a] for a in range(3)], [2048, 1024, 1024])
        # The paper's 64^3 cells per rank, in whatever block shape the halo cost picks; every
        # field holds the block and its halo (3 wide for the WENO5 fields at most, plus padding):
        # between 8 n_x n_y n_z and 8 (n_x + 14)(n_y + 14)(n_z + 14) bytes per field.
        self.assertEqual(local[0] * local[1] * local[2], 64**3)
        # 32 x 16 x 16 placed by halo_cost: the 32 on y (tied with z, where no wall saves a face)
        # rather than x, whose faces are packed strided.
        self.assertEqual(p, [16, 32, 16])
        per_field = field_gib * 2**30 / fields
        self.assertGreater(per_field, 8 * local[0] * local[1] * local[2])
        self.assertLess(per_field, 8 * (local[0] + 14) * (local[1] + 14) * (local[2] + 14))
        self.assertGreaterEqual(fields, 20, "state, work arrays and ACM fields")
        self.assertEqual(snapshot(self.dir), before, "a dry run writes nothing")
        # SOR with Crank-Nicolson keeps the iterate's arrays too; FFT adds its pencils.
        _, _, sor_fields, _ = self.dry_run(8192, "--method", "sor")
        self.assertGreater(sor_fields, fields)
        fft, fft_total, _, _ = self.dry_run(8192, "--method", "fft")
        self.assertGreater(fft_total, total)
        self.assertIn("FFT pencils", fft.out)

    def test_dry_run_memory_matches_a_real_run(self):
        # The estimate counts the solver's arrays; the resident size of a real run adds MPI
        # and the libraries (tens of MB). At 128 x 64 x 64 cells the arrays dominate.
        for method in ("acm", "sor", "fft"):
            with self.subTest(method=method):
                _, estimate, _, _ = self.dry_run(1, "--scale", "16", "--method", method)
                probe = ("import resource, subprocess, sys; "
                         "subprocess.run(sys.argv[1:], check=True, stdout=subprocess.DEVNULL); "
                         "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
                out = subprocess.run([sys.executable, "-c", probe, driver_harness.program_path(self.program),
                                      "--scale", "16", "--method", method, "--steps", "1"],
                                     env=driver_harness.test_env(), capture_output=True, text=True, timeout=300)
                self.assertEqual(out.returncode, 0, out.stderr)
                rss_gib = int(out.stdout.split()[-1]) / 2**20
                self.assertLess(estimate, rss_gib, "the arrays are part of what the run holds")
                if os.environ.get("EFSI_SANITIZED") == "1":
                    continue  # shadow memory and redzones: the resident size is no measure
                self.assertGreater(estimate, 0.7 * rss_gib, "estimate %.3f GiB, resident %.3f GiB" % (estimate, rss_gib))


class NodeMemory(DriverTestCase):
    """The experiment drivers refuse a run the node cannot hold (check_node_memory), as
    channel does; the strong-scaling dry run, which allocates nothing, does not."""

    TINY_KB = 1000

    def test_weak_scaling_refused_on_a_small_node(self):
        self.program = "weak_scaling"
        args = ["--local", "16", "--particles-per-rank", "0", "--steps", "1", "--csv", "weak.csv"]
        before = snapshot(self.dir)
        self.check_memory_refusal(run(args, cwd=self.dir, program=self.program, extra_env=self.fake_node(self.TINY_KB)))
        self.assertEqual(snapshot(self.dir), before, "a refused run writes nothing")
        self.run_ok(args + ["--force-memory"], extra_env=self.fake_node(self.TINY_KB))
        self.assertTrue(os.path.exists(self.path("weak.csv")))

    def test_accuracy_refused_for_both_methods_together(self):
        self.program = "accuracy"
        args = ["--cells", "32", "--length", "3.6", "--t-end", "0.002", "--csv", "acc.csv"]
        before = snapshot(self.dir)
        res = run(args, cwd=self.dir, program=self.program, extra_env=self.fake_node(self.TINY_KB))
        need, _, _ = self.check_memory_refusal(res)
        self.assertEqual(snapshot(self.dir), before, "a refused run writes nothing")
        # ACM's and FFT's solvers live together to the comparison: the node needs their sum.
        alone = [self.check_memory_refusal(run(args + ["--methods", m], cwd=self.dir, program=self.program,
                                               extra_env=self.fake_node(self.TINY_KB)))[0] for m in ("acm", "fft")]
        self.assertAlmostEqual(need, sum(alone), delta=0.01 * need)

    def test_strong_scaling_full_size_refused_but_its_dry_run_is_not(self):
        self.program = "strong_scaling"
        with open("/proc/meminfo") as f:
            available_kb = int(re.search(r"MemAvailable:\s+(\d+) kB", f.read()).group(1))
        if available_kb > 2**30:
            self.skipTest("this node has over 1 TiB available")
        res = run(["--scale", "1", "--steps", "1"], cwd=self.dir, program=self.program, timeout=60)
        need, _, _ = self.check_memory_refusal(res)
        self.assertGreater(need, 100)
        self.assertLess(res.seconds, 30, "refused before allocating")
        res = self.run_ok(["--dry-run", "--ranks", "1"], extra_env=self.fake_node(self.TINY_KB))
        self.assertIn("memory per rank", res.out)


class Accuracy(DriverTestCase):
    program = "accuracy"

    def test_small_case_writes_series_centroids_and_fields(self):
        args = ["--cells", "32", "--length", "3.6", "--t-end", "0.01", "--every", "5", "--csv", "acc.csv"]
        for ranks in (1, 2):
            with self.subTest(ranks=ranks):
                self.run_ok(args, ranks=ranks)
        _, rows = read_table(self.path("acc.csv"))
        self.check_header(rows[0])
        self.assertEqual([r[1] for r in rows[1:]], ["acm", "fft", "acm", "fft"])
        for n, ranks in ((1, 1), (2, 1), (3, 2), (4, 2)):
            self.check_row(rows[0], rows[n], ranks, 1, (32, 32, 32), 19, 2, "sync", experiment="accuracy",
                           method=rows[n][1], dt=5e-4, div_rms_max=1.0)
        for method in ("acm", "fft"):
            _, series = read_table(self.path("series-%s.csv" % method))
            self.assertEqual(series[0][:6], ["step", "time", "kinetic", "input", "eps_solid", "eps_fluid"])
            self.assertEqual([int(r[0]) for r in series[1:]], [0, 5, 10, 15, 20])
            _, centroids = read_table(self.path("centroids-%s.csv" % method))
            self.assertEqual(centroids[0], ["step", "time", "region", "volume", "x", "y", "z"])
            self.assertEqual(len(centroids) - 1, 2 * 5, "two particles at five times")
            with h5py.File(self.path("fields-%s.h5" % method), "r") as f:
                phi = f["phi"][...]
                self.assertEqual(f.attrs["step"], 20)
                self.assertEqual(sorted(f.keys()), sorted(["u", "v", "w", "p", "phi", "Bt11", "Bt22", "Bt33",
                                                           "Bt12", "Bt13", "Bt23"]))
            self.assertEqual(phi.shape, (32, 32, 32))
            self.assertTrue(os.path.isfile(self.path("fields-%s.xmf" % method)))
            # The file holds the final phi: its mean is the series' conserved solid fraction.
            self.assertAlmostEqual(phi.mean(), float(series[-1][10]), delta=1e-9)
            self.assertGreater(phi.max(), 0.9)
        with open(self.path("comparison.txt")) as f:
            text = f.read()
        m = re.search(r"max \|phi diff\| (\S+); centroids (\S+) cells apart", text)
        self.assertIsNotNone(m, text)
        self.assertLess(float(m.group(1)), 1e-2, "ACM and the FFT reference agree over 20 steps")
        self.assertLess(float(m.group(2)), 1e-2)

    def test_force_drives_the_flow(self):
        # From rest the flow's kinetic energy grows as f^2 while it is slow (Stokes start-up).
        args = ["--cells", "32", "--length", "3.6", "--t-end", "0.005", "--every", "10", "--methods", "acm"]
        kinetic = {}
        for force in ("0.5", "1", "2"):
            with self.subTest(force=force):
                self.run_ok(args + ["--force", force])
                _, series = read_table(self.path("series-acm.csv"))
                kinetic[force] = float(series[-1][2])
        self.assertGreater(kinetic["1"], 1e-6)
        self.assertAlmostEqual(kinetic["2"] / kinetic["1"], 4.0, delta=0.04)
        self.assertAlmostEqual(kinetic["0.5"] / kinetic["1"], 0.25, delta=0.0025)

    def test_restart_per_method_continues_bitwise(self):
        # The 128^3 case runs in chunks: each method's checkpoint carries -METHOD in its name,
        # --restart takes the name given to --checkpoint, and the two halves end on the bits of
        # one uninterrupted run, for both methods. FFTW_MEASURE may plan differently in each
        # process (it times the candidates), so the bits need --reproducible.
        box = ["--cells", "32", "--length", "3.6", "--every", "5", "--reproducible"]
        self.run_ok(box + ["--t-end", "0.01", "--out", "."])
        whole = {m: fields_of(self.path("fields-%s.h5" % m)) for m in ("acm", "fft")}
        os.mkdir(self.path("parts"))
        self.run_ok(box + ["--t-end", "0.005", "--out", "parts", "--checkpoint", "parts/ck.h5"])
        self.assertTrue(all(os.path.isfile(self.path("parts/ck-%s.h5" % m)) for m in ("acm", "fft")))
        self.run_ok(box + ["--t-end", "0.01", "--out", "parts", "--restart", "parts/ck.h5"])
        for m in ("acm", "fft"):
            resumed = fields_of(self.path("parts/fields-%s.h5" % m))
            for name, a in whole[m].items():
                self.assertTrue(np.array_equal(a.view(np.uint64), resumed[name].view(np.uint64)),
                                "%s: %s differs by %.3g" % (m, name, np.abs(a - resumed[name]).max()))
        # The file one sees on disk, passed as it is: the error names the file the driver looked for.
        res = run(box + ["--t-end", "0.01", "--methods", "fft", "--out", "parts", "--restart", "parts/ck-fft.h5"],
                  cwd=self.dir, program=self.program)
        self.assertEqual(res.rc, 2, str(res))
        self.assertRegex(res.err, r"^accuracy: error: --restart 'parts/ck-fft\.h5': the checkpoint of method fft is "
                                  r"'parts/ck-fft-fft\.h5' \(the name given with -fft added\), which cannot be "
                                  r"read\n$")

    def test_solid_cutoff_defaults_on_and_is_recorded(self):
        # The accuracy case runs with the cut-off unless told otherwise; the checkpoint records it.
        args = ["--cells", "32", "--length", "3.6", "--t-end", "0.002", "--methods", "acm", "--checkpoint", "ck.h5"]
        for given, recorded in (([], b"0.05"), (["--solid-cutoff", "0"], b"0")):
            with self.subTest(given=given):
                self.run_ok(args + given)
                with h5py.File(self.path("ck-acm.h5"), "r") as f:
                    self.assertEqual(f.attrs["config solid cutoff"], recorded)


class BadOptions(DriverTestCase):
    CASES = [
        ("weak_scaling", ["--method", "simple"], r"--method|simple"),
        ("weak_scaling", ["--particles-per-rank", "5"], r"5|particles"),
        ("weak_scaling", ["--local", "0"], r"--local 0"),
        ("weak_scaling", ["--decomp", "2,1,1"], r"--decomp 2,1,1"),
        ("weak_scaling", ["--comm", "later"], r"later"),
        ("strong_scaling", ["--scale", "3"], r"--scale 3 .*16"),
        ("strong_scaling", ["--scale", "32"], r"--scale 32"),
        ("strong_scaling", ["--method", "multigrid"], r"multigrid"),
        ("strong_scaling", ["--dry-run"], r"--ranks"),
        ("strong_scaling", ["--dry-run", "--ranks", "7"], r"7"),
        ("strong_scaling", ["--ranks", "4"], r"--ranks"),
        ("accuracy", ["--methods", "acm,exact"], r"exact"),
        ("accuracy", ["--out", "no_such_dir"], r"no_such_dir"),
        ("accuracy", ["--cells", "8", "--length", "3.6"], r"."),
        ("accuracy", ["--force", "nan"], r"--force"),
        ("accuracy", ["--solid-cutoff", "1"], r"--solid-cutoff 1\.0+ must be at least 0 and below 1"),
        ("accuracy", ["--solid-cutoff", "-0.01"], r"--solid-cutoff -0\.010*"),
        ("accuracy", ["--solid-cutoff", "nan"], r"--solid-cutoff"),
    ]

    def test_one_line_exit_2_nothing_written(self):
        for program, args, pattern in self.CASES:
            with self.subTest(program=program, args=" ".join(args)):
                before = snapshot(self.dir)
                res = run(args + ["--csv", "x.csv"], cwd=self.dir, program=program)
                self.assertFalse(res.timed_out, str(res))
                self.assertEqual(res.rc, 2, str(res))
                lines = res.err.splitlines()
                self.assertEqual(len(lines), 1, str(res))
                self.assertTrue(lines[0].startswith(program + ": "), lines[0])
                self.assertRegex(lines[0], pattern)
                self.assertEqual(snapshot(self.dir), before, "a rejected run writes nothing")


class UnwritableOutputs(DriverTestCase):
    """Issue 12: every output option of every experiment driver is checked before the run
    (exit 2, one line, nothing created); a VTK image that does not fit fails the run (exit
    5) with no half image and no CSV row."""

    CASES = [
        ("weak_scaling", ["--csv"]),
        ("strong_scaling", ["--csv"]),
        ("accuracy", ["--csv"]),
        ("accuracy", ["--out"]),
    ]

    def test_unwritable_paths_exit_2(self):
        with open(self.path("a_file"), "w") as f:
            f.write("not a directory\n")
        for program, option in self.CASES:
            for path in ("no_such_dir/x.csv", "a_file/x.csv", "/proc/version", "/proc"):
                with self.subTest(program=program, option=option, path=path):
                    before = snapshot(self.dir)
                    res = run(option + [path], cwd=self.dir, program=program)
                    self.assertFalse(res.timed_out, str(res))
                    self.assertEqual(res.rc, 2, str(res))
                    lines = res.err.splitlines()
                    self.assertEqual(len(lines), 1, str(res))
                    self.assertRegex(lines[0], r"^%s: error: .*%s" % (program, re.escape(path)))
                    self.assertEqual(snapshot(self.dir), before, "a rejected run created a file")

    def test_every_method_is_checked_before_the_first_runs(self):
        # The second method's checkpoint name is a folder: refused before the first method's
        # steps, not after them.
        os.mkdir(self.path("ck-fft.h5"))
        before = snapshot(self.dir)
        res = run(["--cells", "32", "--length", "3.6", "--t-end", "0.002", "--methods", "acm,fft",
                   "--checkpoint", "ck.h5"], cwd=self.dir, program="accuracy")
        self.assertEqual(res.rc, 2, str(res))
        self.assertRegex(res.err, r"^accuracy: error: --checkpoint 'ck-fft.h5' is not a regular file\n$")
        self.assertEqual(res.out, "", "the first method ran before the second's outputs were checked")
        self.assertEqual(snapshot(self.dir), before)

    def test_fields_over_a_small_tmpfs(self):
        fs = self.small_tmpfs()
        # 11 fields of 32^3 doubles do not fit in 64 KiB; the series and centroids before them do.
        res = run(["--cells", "32", "--length", "3.6", "--t-end", "0.002", "--every", "1", "--methods", "acm",
                   "--out", fs, "--csv", "acc.csv"], cwd=self.dir, program="accuracy")
        self.assertFalse(res.timed_out, str(res))
        self.assertEqual(res.rc, EXIT_OUTPUT_FAILED, str(res))
        fields = os.path.join(fs, "fields-acm.h5")
        self.assertRegex(res.err, r"^accuracy: error: cannot write %s: No space left on device[^\n]*\n$" %
                         re.escape(fields))
        self.assertEqual(sorted(os.listdir(fs)), ["centroids-acm.csv", "series-acm.csv"])
        self.assertFalse(os.path.exists(self.path("acc.csv")), "a row was recorded for a failed run")


if __name__ == "__main__":
    driver_harness.main()
