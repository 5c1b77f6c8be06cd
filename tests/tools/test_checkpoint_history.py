#!/usr/bin/python3
"""Tests of plots/checkpoint_history.py on a checkpoint the channel driver writes here: the
series and centroids it extracts are byte for byte the files the driver wrote for the same
steps; bad input and failed writes give one line, exit status 2 (usage) or 1 (a file), and
leave no file under a final name.

Usage: test_checkpoint_history.py --bin-dir BUILD/bin [unittest options]
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
TOOL = os.path.join(os.path.dirname(os.path.dirname(HERE)), "plots", "checkpoint_history.py")
BIN_DIR = None


def tool(*args):
    return subprocess.run([sys.executable, TOOL, *args], capture_output=True, text=True, timeout=120)


class CheckpointHistory(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.mkdtemp(prefix="efsi-ckhist-")
        run = os.path.join(cls.tmp, "run")
        os.mkdir(run)
        # 10 steps and the warm-up; the last checkpoint is of the final state, when the driver
        # also closes its series and centroids: the same rows.
        r = subprocess.run([os.path.join(BIN_DIR, "channel"), "--cells", "32", "--length", "3.6", "--particles", "1",
                            "--steps", "10", "--every", "2", "--series", "s.csv", "--centroids", "c.csv",
                            "--checkpoint-every", "5", "--checkpoint", "ck.h5"],
                           cwd=run, capture_output=True, text=True, timeout=240)
        if r.returncode != 0:
            raise RuntimeError("channel failed: " + r.stdout + r.stderr)
        cls.run_dir = run
        cls.checkpoint = os.path.join(run, "ck.h5")

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, True)

    def out_dir(self):
        d = tempfile.mkdtemp(dir=self.tmp)
        return d

    def read(self, *parts):
        with open(os.path.join(*parts), "rb") as f:
            return f.read()

    def assert_one_line(self, r, code, *words):
        self.assertEqual(r.returncode, code, r.stdout + r.stderr)
        lines = r.stderr.strip().splitlines()
        self.assertEqual(len(lines), 1, r.stderr)
        self.assertTrue(lines[0].startswith("checkpoint_history.py: error: "), lines[0])
        for w in words:
            self.assertIn(w, lines[0])

    def test_same_bytes_as_the_driver(self):
        out = self.out_dir()
        r = tool("--out", out, self.checkpoint)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        self.assertEqual(self.read(out, "series-acm.csv"), self.read(self.run_dir, "s.csv"))
        self.assertEqual(self.read(out, "centroids-acm.csv"), self.read(self.run_dir, "c.csv"))
        self.assertIn("6 rows, checkpoint step 11", r.stdout)  # steps 0, 2, ..., 10
        self.assertEqual(sorted(os.listdir(out)), ["centroids-acm.csv", "series-acm.csv"])

    def test_method_name_and_existing_files(self):
        out = self.out_dir()
        self.assertEqual(tool("--out", out, "--method", "acm-x", self.checkpoint).returncode, 0)
        self.assertTrue(os.path.isfile(os.path.join(out, "series-acm-x.csv")))
        with open(os.path.join(out, "series-acm-x.csv"), "w") as f:
            f.write("kept\n")
        r = tool("--out", out, "--method", "acm-x", self.checkpoint)
        self.assert_one_line(r, 2, "series-acm-x.csv", "exists", "--force")
        self.assertEqual(self.read(out, "series-acm-x.csv"), b"kept\n")
        self.assertEqual(tool("--out", out, "--method", "acm-x", "--force", self.checkpoint).returncode, 0)
        self.assertEqual(self.read(out, "series-acm-x.csv"), self.read(self.run_dir, "s.csv"))

    def test_failed_write_leaves_nothing(self):
        out = self.out_dir()
        # The second file's temporary name leads to a full device: the write itself fails.
        os.symlink("/dev/full", os.path.join(out, "centroids-acm.csv.tmp"))
        r = tool("--out", out, self.checkpoint)
        self.assert_one_line(r, 1, "centroids-acm.csv", "No space left on device")
        self.assertEqual(os.listdir(out), [], "the series alone must not be left")
        os.mkdir(os.path.join(out, "series-acm.csv"))
        self.assert_one_line(tool("--out", out, "--force", self.checkpoint), 1, "series-acm.csv", "is a directory")
        self.assertEqual(os.listdir(out), ["series-acm.csv"])

    def test_bad_input(self):
        out = self.out_dir()
        not_hdf5 = os.path.join(self.run_dir, "s.csv")
        self.assert_one_line(tool("--out", out, os.path.join(out, "none.h5")), 2, "none.h5")
        self.assert_one_line(tool("--out", os.path.join(out, "nodir"), self.checkpoint), 2, "nodir")
        self.assert_one_line(tool("--out", out, not_hdf5), 1, not_hdf5)
        self.assert_one_line(tool("--out", out, "--bogus", self.checkpoint), 2, "--bogus")
        self.assertEqual(os.listdir(out), [])


if __name__ == "__main__":
    p = argparse.ArgumentParser()
    p.add_argument("--bin-dir", required=True)
    args, rest = p.parse_known_args()
    BIN_DIR = os.path.abspath(args.bin_dir)
    unittest.main(argv=[sys.argv[0], *rest])
