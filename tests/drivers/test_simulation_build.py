#!/usr/bin/env python3
"""The simulation build (the `simgrid` preset, build-simgrid/): weak_scaling compiled with
SimGrid's smpicxx runs as simulated ranks under smpirun (harness/simgrid/run.sh).

- 2 and 8 simulated ranks of 32^3 each finish, pass their validation and append one CSV row
  that names SMPI as the MPI library and the rank grid of the real build;
- what the simulation build leaves out (parallel HDF5: checkpoints, snapshots, restarts) is
  refused in one line with exit status 2 before the run, nothing written.

    test_simulation_build.py --sim-bin-dir BUILD-SIMGRID/bin --source-dir DIR
"""

import argparse
import csv
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

ARGS = None
LOCAL = ["--local", "32", "--particles-per-rank", "0", "--steps", "2"]


class SimulationBuild(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="efsi_simgrid_")
        self.addCleanup(shutil.rmtree, self.dir, True)
        self.driver = os.path.join(ARGS.sim_bin_dir, "weak_scaling")
        if not os.access(self.driver, os.X_OK):
            self.fail(f"no simulation build at {self.driver}: cmake --preset simgrid && cmake --build --preset simgrid")

    def run_sim(self, ranks, *args):
        run_sh = os.path.join(ARGS.source_dir, "harness", "simgrid", "run.sh")
        platform = os.path.join(ARGS.source_dir, "harness", "simgrid", "platforms", "dev-2core.xml")
        # One node: the 8-rank run shares its 2 cores, as the oversubscribed real tests do.
        return subprocess.run(["bash", run_sh, platform, str(ranks), str(ranks), self.driver, *args], cwd=self.dir,
                              capture_output=True, text=True, timeout=300)

    def test_runs_and_records_a_row(self):
        for ranks, grid in ((2, ("1", "2", "1")), (8, ("2", "2", "2"))):
            with self.subTest(ranks=ranks):
                r = self.run_sim(ranks, *LOCAL, "--csv", "sim.csv")
                self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
                self.assertIn(f"weak_scaling: acm, sync halo, {ranks} ranks as", r.stdout)
                self.assertRegex(r.stdout, r"validation: .*: PASSED")
                with open(os.path.join(self.dir, "sim.csv")) as f:
                    row = list(csv.DictReader(f))[-1]
                self.assertEqual((row["ranks"], row["px"], row["py"], row["pz"]), (str(ranks), *grid))
                self.assertTrue(row["mpi"].startswith("SMPI"), row["mpi"])
                # The node's ranks against this machine's 2 cores, as in the real build.
                self.assertEqual((row["oversubscribed"], row["valid"]), ("1", "0") if ranks > 2 else ("0", "1"))

    def test_state_files_are_refused_before_the_run(self):
        for option in (["--checkpoint", "ck.h5"], ["--snapshot-every", "1"], ["--restart", "ck.h5"]):
            with self.subTest(option=option[0]):
                r = self.run_sim(2, *LOCAL, *option, "--csv", "sim.csv")
                self.assertNotEqual(r.returncode, 0)
                errors = [line for line in r.stderr.splitlines() if line.startswith("weak_scaling: error:")]
                self.assertEqual(len(errors), 1, r.stderr)
                self.assertIn(f"{option[0]}: not in the simulation build: parallel HDF5 links Open MPI", errors[0])
                self.assertNotIn("timing over", r.stdout)
                self.assertEqual([n for n in os.listdir(self.dir) if not n.startswith("smpitmp-")], [])


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--sim-bin-dir", required=True)
    ap.add_argument("--source-dir", required=True)
    ARGS, rest = ap.parse_known_args()
    ARGS.sim_bin_dir, ARGS.source_dir = os.path.abspath(ARGS.sim_bin_dir), os.path.abspath(ARGS.source_dir)
    unittest.main(argv=[sys.argv[0], *rest], verbosity=2)
