#!/usr/bin/env python3
"""The JUBE definition harness/jube/efsi_bench.xml, run for real on the mini sweep.

`jube run --tag mini` starts six runs (1 and 2 ranks, ACM sync, SOR async eps 1e-3 and MG
at its count for 1e-3, the paper's 64^3 block per rank, 2 measured steps) through campaign.py and mpirun; then
`jube result -a` analyses them.  Checked: every workpackage ran, results.csv in the run
directory holds the six rows under one section-8 header, each valid and of the right
configuration, and JUBE's result table reports the same configurations and times.

Usage: test_jube.py --bin-dir BUILD/bin [--jube JUBE] [unittest options]
"""

import csv
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
XML = os.path.join(REPO, "harness", "jube", "efsi_bench.xml")
BIN_DIR = os.environ.get("EFSI_BIN_DIR", "")
JUBE = shutil.which("jube") or "jube"
SECTION8 = ("experiment,method,comm,eps,ranks,threads,px,py,pz,nx,ny,nz,particles,steps,dt,ns_per_step,"
            "nc_per_step,elapsed_s,compute_s,halo_s,reduce_s,comm_s,comm_s_max,comm_fraction,mlups,div_rms,"
            "valid,host,mpi,compiler,git_sha,timestamp").split(",")
EXPECTED = {(r, c) for r in ("1", "2") for c in ("acm-sync", "sor-async-1e-3", "mg-sync-1e-3")}


def config_name(row):
    eps = {"": "", "0.001": "-1e-3", "1e-3": "-1e-3", "0.0001": "-1e-4", "1e-4": "-1e-4"}[row["eps"]]
    return f"{row['method']}-{row['comm']}{eps}"


class JubeMiniSweep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not BIN_DIR:
            raise unittest.SkipTest("no --bin-dir")
        cls.out = tempfile.mkdtemp(prefix="efsi-jube-")
        env = dict(os.environ, EFSI_BIN_DIR=os.path.abspath(BIN_DIR))
        cls.run_ = subprocess.run([JUBE, "run", XML, "--tag", "mini", "-o", cls.out], capture_output=True,
                                  text=True, env=env, timeout=600)
        cls.result = subprocess.run([JUBE, "result", "-a", cls.out, "--id", "0"], capture_output=True, text=True,
                                    env=env, timeout=120)
        cls.rundir = os.path.join(cls.out, "000000")

    @classmethod
    def tearDownClass(cls):
        if hasattr(cls, "out"):
            shutil.rmtree(cls.out, True)

    def test_every_workpackage_ran(self):
        self.assertEqual(self.run_.returncode, 0, self.run_.stdout + self.run_.stderr)
        wps = sorted(d for d in os.listdir(self.rundir) if d.endswith("_run"))
        self.assertEqual(len(wps), 6, wps)
        for wp in wps:
            self.assertTrue(os.path.exists(os.path.join(self.rundir, wp, "done")), f"{wp} did not finish")
            with open(os.path.join(self.rundir, wp, "work", "run.csv")) as f:
                self.assertEqual(len(list(csv.DictReader(f))), 1, wp)

    def test_collected_csv_has_the_sweep_valid(self):
        path = os.path.join(self.rundir, "results.csv")
        with open(path) as f:
            reader = csv.DictReader(f)
            self.assertEqual(reader.fieldnames[:len(SECTION8)], SECTION8)
            rows = list(reader)
        self.assertEqual({(r["ranks"], config_name(r)) for r in rows}, EXPECTED)
        self.assertEqual(len(rows), 6)
        for r in rows:
            self.assertEqual((r["experiment"], r["steps"], r["threads"], r["valid"]), ("weak", "2", "1", "1"), r)
            px, py, pz = int(r["px"]), int(r["py"]), int(r["pz"])
            self.assertEqual(px * py * pz, int(r["ranks"]))
            self.assertEqual((int(r["nx"]) // px, int(r["ny"]) // py, int(r["nz"]) // pz), (64, 64, 64))
            self.assertEqual(int(r["particles"]), 2 * int(r["ranks"]))
            self.assertGreater(float(r["elapsed_s"]), 0)
            self.assertGreaterEqual(float(r["comm_fraction"]), 0)
            self.assertLess(float(r["comm_fraction"]), 1)

    def test_jube_result_table_matches_the_csv(self):
        self.assertEqual(self.result.returncode, 0, self.result.stdout + self.result.stderr)
        table = os.path.join(self.rundir, "result", "results.dat")
        with open(table) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual({(r["ranks"], r["config"]) for r in rows}, EXPECTED)
        with open(os.path.join(self.rundir, "results.csv")) as f:
            elapsed = {(r["ranks"], config_name(r)): float(r["elapsed_s"]) for r in csv.DictReader(f)}
        for r in rows:
            self.assertEqual((r["sweep"], r["threads"], r["repeat"], r["valid"]), ("mini", "1", "1", "1"), r)
            self.assertAlmostEqual(float(r["elapsed_s"]), elapsed[(r["ranks"], r["config"])],
                                   delta=1e-6 * elapsed[(r["ranks"], r["config"])])
            nx, ny, nz = int(r["nx"]), int(r["ny"]), int(r["nz"])
            self.assertEqual(nx * ny * nz, 64 ** 3 * int(r["ranks"]))


if __name__ == "__main__":
    for flag in ("--bin-dir", "--jube"):
        if flag in sys.argv:
            i = sys.argv.index(flag)
            if flag == "--bin-dir":
                BIN_DIR = sys.argv[i + 1]
            else:
                JUBE = sys.argv[i + 1]
            del sys.argv[i:i + 2]
    unittest.main()
