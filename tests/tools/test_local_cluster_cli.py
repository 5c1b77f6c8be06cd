#!/usr/bin/env python3
"""harness/slurm-local/local_cluster.py when it must refuse: one line, a non-zero status, nothing left.

- A bad option is one line and exit status 2; so is a port outside 1024..65535.
- A port that is taken, or not being root, is one line naming the cause and exit status 1,
  before any daemon starts: no pids.json, no slurm.conf.
- stop and status on a directory where nothing runs say so (stop: status 0; status: 1).
No daemon is started here (test_slurm_local.py starts the cluster).
"""

import os
import shutil
import socket
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
TOOL = os.path.join(os.path.dirname(os.path.dirname(HERE)), "harness", "slurm-local", "local_cluster.py")


def tool(*args):
    return subprocess.run([sys.executable, TOOL, *args], capture_output=True, text=True, timeout=60)


class Refusals(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.mkdtemp(prefix="efsi-slurm-cli-")
        self.addCleanup(shutil.rmtree, self.dir, True)

    def assert_one_line(self, r, status, needle):
        self.assertEqual(r.returncode, status, r.stdout + r.stderr)
        lines = r.stderr.splitlines()
        self.assertEqual(len(lines), 1, r.stderr)
        self.assertTrue(lines[0].startswith("local_cluster.py: error: "), lines[0])
        self.assertIn(needle, lines[0])

    def assert_nothing_started(self):
        self.assertFalse(os.path.exists(os.path.join(self.dir, "pids.json")))
        self.assertFalse(os.path.exists(os.path.join(self.dir, "slurm.conf")))

    def test_bad_options(self):
        for args, needle in ((["start", "--dir", self.dir, "--ports", "80,6818"], "80,6818"),
                             (["start", "--dir", self.dir, "--ports", "6817"], "6817"),
                             (["start", "--dir", self.dir, "--timeout", "0"], "'0'"),
                             (["start", "--dir", self.dir, "--task-plugin", "cgroup"], "cgroup"),
                             (["launch"], "launch")):
            with self.subTest(args=args):
                self.assert_one_line(tool(*args), 2, needle)
                self.assert_nothing_started()

    def test_a_taken_port_is_named(self):
        if os.geteuid() != 0:
            self.skipTest("the root check comes first")
        with socket.socket() as busy:
            busy.bind(("127.0.0.1", 0))
            busy.listen()
            port = busy.getsockname()[1]
            with socket.socket() as s:
                s.bind(("127.0.0.1", 0))
                other = s.getsockname()[1]
            r = tool("start", "--dir", self.dir, "--ports", f"{port},{other}")
        self.assert_one_line(r, 1, f"port {port} is taken")
        self.assert_nothing_started()

    def test_not_root_is_refused(self):
        if os.geteuid() == 0:
            setpriv = shutil.which("setpriv")
            if not setpriv:
                self.skipTest("setpriv (util-linux) not found")
            # The other user runs a copy of the script from a folder it can reach: the clone
            # may live where only its owner can read (mktemp -d, root's home), and so may
            # TMPDIR, so the folder is made under /tmp itself.
            shared = tempfile.mkdtemp(prefix="efsi-slurm-cli-other-", dir="/tmp")
            self.addCleanup(shutil.rmtree, shared, True)
            os.chmod(shared, 0o777)
            script = os.path.join(shared, os.path.basename(TOOL))
            shutil.copyfile(TOOL, script)
            os.chmod(script, 0o644)
            self.dir = shared
            cmd = [setpriv, "--reuid=65534", "--regid=65534", "--clear-groups", sys.executable, script, "start",
                   "--dir", self.dir]
            r = subprocess.run(cmd, capture_output=True, text=True, timeout=60)
        else:
            r = tool("start", "--dir", self.dir)
        self.assert_one_line(r, 1, "needs root")
        self.assert_nothing_started()

    def test_stop_and_status_when_nothing_runs(self):
        r = tool("stop", "--dir", self.dir)
        self.assertEqual(r.returncode, 0, r.stderr)
        self.assertIn("nothing of", r.stdout)
        r = tool("status", "--dir", self.dir)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("slurmctld  not running", r.stdout)


if __name__ == "__main__":
    unittest.main()
