#!/usr/bin/env python3
"""The suite passes from a clone that only its owner can read (mktemp -d, root's home: 0700).

A test that runs something as another user (setpriv, runuser, su) cannot reach such a clone:
it must copy what that user runs to a folder the user can reach.  This test

- finds every test source that switches user, and fails on one it does not rerun below,
  so that a new one cannot slip past it;
- copies the tracked tree (or, outside git, the folders those tests read) into a 0700 folder,
  checks that another user really cannot read the copy, and runs those tests from there.

  test_private_clone.py --source-dir DIR
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest

# The tests that run something as another user, relative to the source tree; each needs no
# build.  A test that switches user and is missing here fails test_every_user_switch_is_rerun.
RERUN = ["tests/tools/test_local_cluster_cli.py"]
SWITCHES_USER = re.compile(r"\bsetpriv\b|\brunuser\b|\bsu\s+-|os\.set(e|re|res)?uid\(")
OTHER_UID = 65534  # nobody
SOURCE = None


def tracked_files(src):
    r = subprocess.run(["git", "-C", src, "ls-files", "-z"], capture_output=True, text=True)
    if r.returncode != 0:
        return None
    return [f for f in r.stdout.split("\0") if f]


def copy_tree(src, dst):
    files = tracked_files(src)
    if files is None:  # a tarball, not a clone: the folders the rerun tests read
        for top in ("harness", "tests"):
            shutil.copytree(os.path.join(src, top), os.path.join(dst, top), symlinks=True)
        return
    for f in files:
        s, d = os.path.join(src, f), os.path.join(dst, f)
        if not os.path.lexists(s):  # deleted in the work tree, not yet committed
            continue
        os.makedirs(os.path.dirname(d), exist_ok=True)
        shutil.copy2(s, d, follow_symlinks=False)


class PrivateClone(unittest.TestCase):
    def test_every_user_switch_is_rerun(self):
        found = []
        for root, dirs, files in os.walk(os.path.join(SOURCE, "tests")):
            for name in files:
                if name.endswith((".py", ".sh", ".cmake", ".txt")) and name != os.path.basename(__file__):
                    path = os.path.join(root, name)
                    with open(path, encoding="utf-8", errors="replace") as f:
                        if SWITCHES_USER.search(f.read()):
                            found.append(os.path.relpath(path, SOURCE))
        self.assertIn(RERUN[0], found, "the user switch this test knows of is no longer found: update RERUN")
        self.assertEqual(sorted(found), sorted(RERUN),
                         "tests that run as another user must be rerun from a private clone (RERUN)")

    def test_rerun_from_a_private_clone(self):
        private = tempfile.mkdtemp(prefix="efsi-private-clone-")
        self.addCleanup(shutil.rmtree, private, True)
        os.chmod(private, 0o700)
        clone = os.path.join(private, "main")
        copy_tree(SOURCE, clone)
        if os.geteuid() == 0 and shutil.which("setpriv"):
            probe = os.path.join(clone, RERUN[0])
            r = subprocess.run(["setpriv", f"--reuid={OTHER_UID}", f"--regid={OTHER_UID}", "--clear-groups",
                                "test", "-r", probe])
            self.assertNotEqual(r.returncode, 0, f"user {OTHER_UID} can read {probe}: the clone is not private")
        for test in RERUN:
            with self.subTest(test=test):
                r = subprocess.run([sys.executable, os.path.join(clone, test)], capture_output=True, text=True,
                                   timeout=300, cwd=clone)
                self.assertEqual(r.returncode, 0, f"{test} from a 0700 clone:\n{r.stdout}{r.stderr}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--source-dir", required=True)
    args, rest = ap.parse_known_args()
    SOURCE = os.path.abspath(args.source_dir)
    unittest.main(argv=[sys.argv[0], *rest])
