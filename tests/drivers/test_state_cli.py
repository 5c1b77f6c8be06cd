#!/usr/bin/env python3
"""End-to-end tests of the solver's state on disk (docs/architecture.md, "Checkpoints and
snapshots"), through `channel`'s command line:

- snapshots: parallel HDF5 datasets identical whatever the decomposition that wrote them, and
  an XDMF file that places each staggering where its values live;
- checkpoint and restart: bitwise continuation on the same rank count for every method and
  halo mode, within the decomposition-invariance tolerance on another, the run's series
  continued across the restart, a checkpoint of another configuration refused;
- failures: a full file system or an unwritable path for --checkpoint and --snapshot-prefix
  (exit 5 or 2, one line, no file under the final name, the previous checkpoint kept), and a
  run killed while writing a checkpoint leaves the previous one readable.

Debian's /usr/bin/python3 with h5py and numpy.  Usage:

    test_state_cli.py --bin-dir BUILD/bin [unittest options]
"""

import os
import re
import signal
import time
import xml.etree.ElementTree as ET

import h5py
import numpy as np

import driver_harness
from driver_harness import *  # noqa: F401,F403 (launching, tables, row checks)

FIELDS = ("u", "v", "w", "p", "phi", "Bt11", "Bt22", "Bt33", "Bt12", "Bt13", "Bt23")
# Where each field's points sit: the axes (x, y, z) it lies on faces of.
FACES = {"u": "x", "v": "y", "w": "z", "p": "", "phi": "", "Bt11": "", "Bt22": "", "Bt33": "",
         "Bt12": "xy", "Bt13": "xz", "Bt23": "yz"}
# The smallest box with the two lattice particles.
BOX = ["--cells", "32", "--length", "3.6"]
SMAC_DT = ["--dt", "6.25e-5"]
# The tolerance of the decomposition-invariance tests (tests/pressure/acm/test_acm_solver.cpp):
# 1e-12 of each field's largest magnitude.
INVARIANCE = 1e-12


def fields_of(path):
    with h5py.File(path, "r") as f:
        return {name: f[name][...] for name in FIELDS}, dict(f.attrs)


def same_bits(a, b):
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))


class StateTestCase(DriverTestCase):
    program = "channel"

    def assert_bitwise(self, a_path, b_path, what):
        a, _ = fields_of(a_path)
        b, _ = fields_of(b_path)
        for name in FIELDS:
            self.assertTrue(same_bits(a[name], b[name]),
                            "%s: %s differs by %.3g" % (what, name, np.abs(a[name] - b[name]).max()))

    def assert_close(self, a_path, b_path, what):
        a, _ = fields_of(a_path)
        b, _ = fields_of(b_path)
        for name in FIELDS:
            scale = max(np.abs(a[name]).max(), 1e-300)
            self.assertLessEqual(np.abs(a[name] - b[name]).max(), INVARIANCE * scale, "%s: %s" % (what, name))

    def launch(self, args, ranks=1):
        return self.run_ok(args, ranks=ranks)

    def one_line_error(self, res, status, pattern):
        self.assertFalse(res.timed_out, str(res))
        self.assertEqual(res.rc, status, str(res))
        lines = res.err.splitlines()
        self.assertEqual(len(lines), 1, "expected one line on stderr:\n%s" % res)
        self.assertRegex(lines[0], pattern)


class Snapshots(StateTestCase):
    def test_datasets_do_not_depend_on_the_decomposition(self):
        # The state at step 0 and after two steps of the FFT reference, written from 1, 2, 4
        # and 8 ranks (rank grids 1x1x1 to 2x2x2 ... as the method chooses).
        for ranks in (1, 2, 4, 8):
            self.launch(BOX + SMAC_DT + ["--method", "fft", "--reproducible", "--steps", "2", "--snapshot-every", "3",
                                         "--snapshot-prefix", "r%d" % ranks], ranks=ranks)
        for ranks in (2, 4, 8):
            with self.subTest(ranks=ranks):
                self.assert_bitwise(self.path("r1-00000000.h5"), self.path("r%d-00000000.h5" % ranks),
                                    "step 0 from %d ranks" % ranks)
                self.assert_close(self.path("r1-00000003.h5"), self.path("r%d-00000003.h5" % ranks),
                                  "step 3 from %d ranks" % ranks)
        fields, attrs = fields_of(self.path("r1-00000003.h5"))
        self.assertEqual(attrs["step"], 3)
        self.assertAlmostEqual(attrs["time"], 3 * 6.25e-5, delta=1e-15)
        # Two particles of volume fraction ~ 2 x 3.2 / 3.6^3 in the box; a flow has started.
        self.assertGreater(fields["phi"].mean(), 0.05)
        self.assertGreater(np.abs(fields["u"]).max(), 0.0)

    def test_xdmf_places_each_staggering(self):
        self.launch(BOX + ["--steps", "1", "--snapshot-every", "2", "--snapshot-prefix", "s"])
        h5 = self.path("s-00000002.h5")
        root = ET.parse(self.path("s-00000002.xmf")).getroot()
        seen = set()
        with h5py.File(h5, "r") as f:
            for grid in root.iter("Grid"):
                if grid.get("GridType") != "Uniform":
                    continue
                dims = [int(v) for v in grid.find("Topology").get("Dimensions").split()]
                origin, spacing = ([float(v) for v in item.text.split()] for item in grid.find("Geometry"))
                for attr in grid.findall("Attribute"):
                    name = attr.get("Name")
                    seen.add(name)
                    self.assertEqual(attr.get("Center"), "Node")
                    # z, y, x order, as the datasets.
                    for k, axis in enumerate("zyx"):
                        on_face = axis in FACES[name]
                        expect = 32 + (1 if axis == "y" and on_face else 0)
                        self.assertEqual(dims[k], expect, "%s along %s" % (name, axis))
                        self.assertAlmostEqual(origin[k], 0.0 if on_face else 0.5 * 3.6 / 32, delta=1e-15)
                        self.assertAlmostEqual(spacing[k], 3.6 / 32, delta=1e-15)
                    file_name, dataset = attr.find("DataItem").text.strip().split(":/")
                    self.assertEqual(file_name, os.path.basename(h5))
                    self.assertEqual(list(f[dataset].shape), dims)
        self.assertEqual(seen, set(FIELDS))


class Restart(StateTestCase):
    def run_interrupted(self, args, ranks, restart_ranks=None, steps=6, at=3):
        """An uninterrupted run of `steps` measured steps against one checkpointed after
        `at` and restarted (on `restart_ranks`); returns the two final checkpoints."""
        full, part, resumed = self.path("full.h5"), self.path("part.h5"), self.path("resumed.h5")
        self.launch(args + ["--steps", str(steps), "--every", "1", "--series", "full.csv", "--checkpoint", full],
                    ranks=ranks)
        self.launch(args + ["--steps", str(at), "--every", "1", "--series", "part.csv", "--checkpoint", part],
                    ranks=ranks)
        res = self.launch(args + ["--steps", str(steps), "--every", "1", "--series", "resumed.csv", "--restart", part,
                                  "--checkpoint", resumed], ranks=restart_ranks or ranks)
        self.assertRegex(res.out, r"restarted from .*part\.h5 at step %d" % (at + 1))
        return full, resumed

    def test_bitwise_on_the_same_rank_count(self):
        cases = [
            (["--method", "acm"], 1),
            (["--method", "acm", "--comm", "async"], 2),
            (["--method", "acm", "--integrator", "rk3"], 2),
            (["--method", "sor", "--eps", "1e-3"] + SMAC_DT, 2),
            (["--method", "sor", "--eps", "1e-3", "--comm", "async"] + SMAC_DT, 2),
            (["--method", "fft", "--reproducible"] + SMAC_DT, 2),
            (["--method", "mg", "--eps", "1e-3", "--mg-iters", "5"] + SMAC_DT, 2),
        ]
        for method, ranks in cases:
            with self.subTest(method=" ".join(method), ranks=ranks):
                full, resumed = self.run_interrupted(BOX + method, ranks)
                self.assert_bitwise(full, resumed, " ".join(method))
                # The series carried in the checkpoint: the resumed file is the whole run's.
                with open(self.path("full.csv")) as a, open(self.path("resumed.csv")) as b:
                    self.assertEqual(a.read(), b.read())
                _, attrs = fields_of(resumed)
                self.assertEqual(attrs["step"], 7)

    def test_another_rank_count_within_the_invariance_tolerance(self):
        for ranks, restart_ranks in ((2, 1), (2, 4), (1, 8)):
            with self.subTest(ranks=ranks, restart_ranks=restart_ranks):
                full, resumed = self.run_interrupted(BOX + ["--method", "acm"], ranks, restart_ranks)
                self.assert_close(full, resumed, "%d -> %d ranks" % (ranks, restart_ranks))

    def test_checkpoint_every_and_at_the_end(self):
        res = self.launch(BOX + ["--steps", "4", "--checkpoint-every", "2"])
        self.assertRegex(res.out, r"state output: 3 checkpoint")  # steps 2 and 4, then 5 at the end
        _, attrs = fields_of(self.path("checkpoint.h5"))
        self.assertEqual(attrs["step"], 5)
        self.assertEqual(attrs["config method"], b"acm")
        self.assertNotIn("checkpoint.h5.tmp", os.listdir(self.dir))

    def test_another_configuration_is_refused(self):
        self.launch(BOX + ["--steps", "1", "--checkpoint", "ck.h5"])
        for change, key in ((["--dt", "1e-5"], "dt"), (["--G", "40"], "G"), (["--method", "fft"], "method"),
                            (["--cells", "32,32,64", "--length", "3.6,3.6,7.2"], "cells"),
                            (["--integrator", "rk3"], "integrator"), (["--solid-cutoff", "0.01"], "solid cutoff")):
            with self.subTest(key=key):
                box = [] if key == "cells" else BOX
                args = box + change + ["--steps", "4", "--restart", "ck.h5", "--csv", "run.csv"]
                before = snapshot(self.dir)
                res = run(args, cwd=self.dir)
                self.one_line_error(res, 2, r"--restart 'ck\.h5' was written with %s = .*; this run has %s = " % (key, key))
                self.assertEqual(snapshot(self.dir), before, "a refused restart wrote something")

    def test_not_a_checkpoint_and_nothing_left_to_run(self):
        with open(self.path("text.h5"), "w") as f:
            f.write("not HDF5\n")
        self.one_line_error(run(BOX + ["--restart", "text.h5"], cwd=self.dir), 2,
                            r"--restart 'text\.h5' is not a readable checkpoint")
        self.one_line_error(run(BOX + ["--restart", "missing.h5"], cwd=self.dir), 2, r"'missing\.h5' cannot be read")
        self.launch(BOX + ["--steps", "2", "--checkpoint", "ck.h5"])
        self.one_line_error(run(BOX + ["--steps", "2", "--restart", "ck.h5"], cwd=self.dir), 2,
                            r"is at step 3 and the run ends at step 3")


class FailedStateOutputs(StateTestCase):
    SMALL = ["--cells", "16", "--particles", "0"]

    def test_full_file_system(self):
        # Too small for the file, and full to the last byte. Was, when full: HDF5 could not
        # write even the superblock of the empty file it closes after the error, and crashed
        # in MPI_Finalize (exit 139 on 1 rank, a hang on 2).
        for option in ("--checkpoint", "--snapshot-prefix"):
            for ranks, full in ((1, False), (2, False), (1, True), (2, True)):
                with self.subTest(option=option, ranks=ranks, full=full):
                    fs = self.small_tmpfs(full=full)
                    target = os.path.join(fs, "state")
                    args = self.SMALL + ["--steps", "2", option, target, "--csv", "run.csv"]
                    if option == "--snapshot-prefix":
                        args += ["--snapshot-every", "1"]
                    if ranks == 1:
                        res = run(args, cwd=self.dir)
                    else:
                        res, statuses = self.run_on_two_ranks(args)
                        self.assertEqual(statuses, {"rank0": "5", "rank1": "5"}, str(res))
                    self.assertFalse(res.timed_out, str(res))
                    self.assertEqual(len(res.err.splitlines()), 1, str(res))
                    self.assertRegex(res.err, r"^channel: error: cannot write %s.*No space left on device" %
                                     re.escape(target))
                    self.assertEqual(os.listdir(fs), ["filler"] if full else [],
                                     "a half file or a temporary stays behind")
                    self.assertFalse(os.path.exists(self.path("run.csv")), "a row was recorded for a failed run")

    def test_previous_checkpoint_kept_when_the_next_does_not_fit(self):
        # Room for one checkpoint of 16^3 (about 0.4 MB, 0.6 MB reserved while written) but
        # not for the next beside it: the first stays, whole, under its name.
        if os.geteuid() != 0:
            self.skipTest("mounting a tmpfs needs root")
        mnt = tempfile.mkdtemp(prefix="efsi_tmpfs_")
        self.addCleanup(os.rmdir, mnt)
        subprocess.run(["mount", "-t", "tmpfs", "-o", "size=900k", "tmpfs", mnt], check=True)
        self.addCleanup(subprocess.run, ["umount", mnt], check=True)
        ck = os.path.join(mnt, "ck.h5")
        res = run(self.SMALL + ["--steps", "3", "--checkpoint-every", "1", "--checkpoint", ck], cwd=self.dir)
        self.assertEqual(res.rc, 5, str(res))
        self.assertEqual(sorted(os.listdir(mnt)), ["ck.h5"])
        fields, attrs = fields_of(ck)
        self.assertEqual(attrs["step"], 1)
        self.assertEqual(fields["u"].shape, (16, 16, 16))

    def test_unwritable_paths_are_refused_before_the_run(self):
        for option, value in (("--checkpoint", "no_such_dir/ck.h5"), ("--snapshot-prefix", "no_such_dir/s"),
                              ("--checkpoint", "/dev/full"), ("--snapshot-prefix", "/dev/full")):
            with self.subTest(option=option, value=value):
                before = snapshot(self.dir)
                res = run(self.SMALL + ["--steps", "2", "--snapshot-every", "1", option, value], cwd=self.dir)
                self.one_line_error(res, 2, re.escape(option))
                self.assertEqual(snapshot(self.dir), before)

    def test_killed_while_writing_a_checkpoint(self):
        # A checkpoint every step of the 64^3 block (about 24 MB each); the run is killed as
        # soon as a new one is being written beside a complete one.
        args = ["--cells", "64", "--length", "3.6", "--steps", "400", "--checkpoint-every", "1", "--checkpoint", "ck.h5"]
        proc = start(args, cwd=self.dir)
        ck, tmp = self.path("ck.h5"), self.path("ck.h5.tmp")
        deadline = time.monotonic() + RUN_TIMEOUT
        caught = False
        while time.monotonic() < deadline and proc.poll() is None:
            if os.path.exists(ck) and os.path.exists(tmp):
                kill_session(proc.pid)
                caught = True
                break
            time.sleep(0.001)
        proc.communicate()
        self.assertTrue(caught, "the run ended before a second checkpoint was seen being written")
        self.assertTrue(os.path.exists(tmp), "killed while writing: the temporary stays")
        fields, attrs = fields_of(ck)
        step = int(attrs["step"])
        self.assertGreaterEqual(step, 1)
        self.assertEqual(fields["v"].shape, (64, 65, 64))
        # Was: the killed run left Open MPI's per-file-name semaphore (OMPIO's shared file
        # pointer, /dev/shm/sem.OMPIO_ck.h5.tmp) taken, and the next checkpoint of that name
        # waited for it forever.
        res = self.launch(["--cells", "64", "--length", "3.6", "--steps", str(step + 1), "--restart", "ck.h5",
                           "--checkpoint", "ck.h5"])
        self.assertRegex(res.out, r"restarted from ck\.h5 at step %d" % step)


if __name__ == "__main__":
    driver_harness.main()
