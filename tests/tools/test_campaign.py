#!/usr/bin/env python3
"""Tests of harness/campaign.py: SLURM scripts, local runs, one-line errors, list and collect.

- The generated SLURM scripts pass `bash -n` and request what their sweep needs: ntasks =
  ranks, nodes, ntasks-per-node, cpus-per-task and OMP_NUM_THREADS (flat and hybrid), a time
  limit, every configuration once per repeat, the paper's rank counts (weak 1..8192, strong
  1024..8192 at --scale 1).
- One generated script is run for real, through a stand-in `srun` that starts mpirun: the
  options it hands the driver are accepted and the row lands in the job's CSV under rows/.
  (test_slurm_local.py submits them to a real SLURM.)
- `--launcher mpirun` places ranks and threads per node as sbatch asked them.
- `local` runs the driver through mpirun and appends a valid row; --dry-run marks
  oversubscribed launches.
- Bad options give one line on stderr and exit status 2, and write nothing.

Usage: test_campaign.py --bin-dir BUILD/bin [unittest options]   (or EFSI_BIN_DIR)
"""

import csv
import math
import os
import re
import shutil
import stat
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
CAMPAIGN = os.path.join(REPO, "harness", "campaign.py")
BIN_DIR = os.environ.get("EFSI_BIN_DIR", "")
MPIEXEC = os.environ.get("EFSI_MPIEXEC") or shutil.which("mpiexec") or shutil.which("mpirun") or "mpirun"
PAPER_CONFIGS = ["acm-sync", "sor-sync-1e-3", "sor-async-1e-3", "sor-sync-1e-4", "sor-async-1e-4"]
# and the multigrid the paper left open, and SOR with temporal blocking (4 sweeps an exchange)
CLUSTER_CONFIGS = PAPER_CONFIGS + ["mg-sync-1e-3", "mg-sync-1e-4", "sor-sync-1e-3-k4", "sor-async-1e-3-k4",
                                   "sor-sync-1e-4-k4", "sor-async-1e-4-k4"]
CONFIG_ARGS = {  # the driver options each configuration must pass
    "acm-sync": "--method acm --comm sync",
    "sor-sync-1e-3": "--method sor --comm sync --eps 1e-3",
    "sor-async-1e-3": "--method sor --comm async --eps 1e-3",
    "sor-sync-1e-4": "--method sor --comm sync --eps 1e-4",
    "sor-async-1e-4": "--method sor --comm async --eps 1e-4",
    "mg-sync-1e-3": "--method mg --comm sync --eps 1e-3 --mg-iters 5",
    "mg-sync-1e-4": "--method mg --comm sync --eps 1e-4 --mg-iters 7",
    "sor-sync-1e-3-k4": "--method sor --comm sync --eps 1e-3 --sweeps-per-exchange 4",
    "sor-async-1e-3-k4": "--method sor --comm async --eps 1e-3 --sweeps-per-exchange 4",
    "sor-sync-1e-4-k4": "--method sor --comm sync --eps 1e-4 --sweeps-per-exchange 4",
    "sor-async-1e-4-k4": "--method sor --comm async --eps 1e-4 --sweeps-per-exchange 4",
}


def campaign(*args, env=None, timeout=600):
    return subprocess.run([sys.executable, CAMPAIGN, *args], capture_output=True, text=True, timeout=timeout,
                          env=env)


def scratch_for_runs(test, prefix):
    """A temporary directory for a test that starts the drivers (skipped without --bin-dir)."""
    if not BIN_DIR:
        test.skipTest("no --bin-dir")
    work = tempfile.mkdtemp(prefix=prefix)
    test.addCleanup(shutil.rmtree, work, True)
    return work


def only_row(test, path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    test.assertEqual(len(rows), 1, path)
    return rows[0]


def sbatch_options(text):
    """#SBATCH --key=value lines -> dict."""
    out = {}
    for m in re.finditer(r"^#SBATCH --([a-z-]+)(?:=(\S+))?\s*$", text, re.M):
        out[m.group(1)] = m.group(2) if m.group(2) is not None else True
    return out


class SlurmScripts(unittest.TestCase):
    def generate(self, *extra):
        out = tempfile.mkdtemp(prefix="efsi-slurm-")
        self.addCleanup(shutil.rmtree, out, True)
        r = campaign("slurm", "--out", out, "--bin-dir", "/opt/efsi/bin", *extra)
        self.assertEqual(r.returncode, 0, r.stderr)
        scripts = sorted(f for f in os.listdir(out) if f.endswith(".sbatch"))
        return out, scripts

    def check_script(self, path, ranks, cpus, cores_per_node, driver, configs, repeats=1, time=None):
        with open(path) as f:
            text = f.read()
        r = subprocess.run(["bash", "-n", path], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, f"{path}: {r.stderr}")
        opt = sbatch_options(text)
        rpn = cores_per_node // cpus
        self.assertEqual(int(opt["ntasks"]), ranks, path)
        self.assertEqual(int(opt["cpus-per-task"]), cpus, path)
        self.assertEqual(int(opt["nodes"]), math.ceil(ranks / rpn), path)
        self.assertEqual(int(opt["ntasks-per-node"]), min(ranks, rpn), path)
        self.assertLessEqual(int(opt["ntasks-per-node"]) * cpus, cores_per_node, path)
        self.assertIn("time", opt, path)
        if time:
            self.assertEqual(opt["time"], time, path)
        self.assertRegex(text, rf"(?m)^export OMP_NUM_THREADS={cpus}$")
        runs = [l for l in text.splitlines() if l.startswith("run srun ")]
        self.assertEqual(len(runs), len(configs) * repeats, path)
        for line in runs:
            # Open MPI starts under srun only through a PMI that the site's MpiDefault may not name.
            self.assertTrue(line.startswith("run srun --mpi=pmix "), line)
            self.assertIn(f"--ntasks={ranks} ", line)
            self.assertIn(f"--cpus-per-task={cpus} ", line)
            self.assertIn(f'"$BIN/{driver}"', line)
            self.assertIn('--csv "$CSV"', line)
        for c in configs:
            hits = [l for l in runs if f"{CONFIG_ARGS[c]} " in l and l.endswith(f"# {c}, repeat 1")]
            self.assertEqual(len(hits), 1, f"{path}: {c}")
        return text, opt

    def test_weak_and_strong_sweeps_at_the_paper_sizes(self):
        out, scripts = self.generate("--account", "proj1", "--partition", "batch")
        weak = [2 ** k for k in range(14)]
        strong = [1024, 2048, 4096, 8192]
        self.assertEqual(scripts, sorted([f"efsi-weak-{r:05d}.sbatch" for r in weak] +
                                         [f"efsi-strong-{r:05d}.sbatch" for r in strong]))
        for r in weak:
            text, opt = self.check_script(os.path.join(out, f"efsi-weak-{r:05d}.sbatch"), r, 1, 8,
                                          "weak_scaling", CLUSTER_CONFIGS)
            self.assertEqual(opt["account"], "proj1")
            self.assertEqual(opt["partition"], "batch")
            self.assertNotIn("--scale", text)       # the driver's defaults are the paper's block
            self.assertNotIn("--local", text)
        for r in strong:
            text, _ = self.check_script(os.path.join(out, f"efsi-strong-{r:05d}.sbatch"), r, 1, 8,
                                        "strong_scaling", CLUSTER_CONFIGS)
            for line in text.splitlines():
                if line.startswith("run srun"):
                    self.assertIn("--scale 1 ", line)
            self.assertIn(f'run "$BIN/strong_scaling" --dry-run --ranks {r} --scale 1', text)
        # submit_all.sh submits each script once; the manifest lists them with their nodes.
        with open(os.path.join(out, "submit_all.sh")) as f:
            submit = f.read()
        self.assertEqual(subprocess.run(["bash", "-n", os.path.join(out, "submit_all.sh")]).returncode, 0)
        listed = re.findall(r"(?m)^for script in (.*); do$", submit)
        self.assertEqual(len(listed), 1, submit)
        self.assertEqual(sorted(listed[0].split()), scripts)
        self.assertIn('sbatch --parsable "$@" "$script"', submit)
        with open(os.path.join(out, "manifest.csv")) as f:
            manifest = list(csv.DictReader(f))
        self.assertEqual(sorted(m["script"] for m in manifest), scripts)
        m8192 = next(m for m in manifest if m["script"] == "efsi-weak-08192.sbatch")
        self.assertEqual((m8192["ranks"], m8192["nodes"]), ("8192", "1024"))
        self.assertEqual(m8192["rows"], "rows/efsi-weak-08192-JOBID.csv")

    def test_hybrid_runs_ask_for_threads(self):
        out, scripts = self.generate("--sweep", "weak", "--ranks", "1,12,13,8192", "--cores-per-node", "48",
                                     "--cpus-per-task", "4", "--time", "01:15:00", "--repeats", "2",
                                     "--configs", "acm-sync,sor-async-1e-4")
        self.assertEqual(len(scripts), 4)
        for r in (1, 12, 13, 8192):
            self.check_script(os.path.join(out, f"efsi-weak-{r:05d}.sbatch"), r, 4, 48, "weak_scaling",
                              ["acm-sync", "sor-async-1e-4"], repeats=2, time="01:15:00")

    def test_mpirun_inside_the_allocation(self):
        out, scripts = self.generate("--sweep", "weak", "--ranks", "1,16", "--cores-per-node", "8",
                                     "--cpus-per-task", "2", "--launcher", "mpirun", "--configs", "acm-sync",
                                     "--rows-dir", "/scratch/efsi/rows")
        with open(os.path.join(out, "efsi-weak-00016.sbatch")) as f:
            text = f.read()
        self.assertEqual(sbatch_options(text)["ntasks-per-node"], "4")
        self.assertIn('run mpirun -n 16 --map-by ppr:4:node:PE=2 --bind-to core "$BIN/weak_scaling" '
                      '--method acm --comm sync --csv "$CSV"', text)
        self.assertNotIn("run srun", text)
        self.assertIn("ROWS=/scratch/efsi/rows\n", text)
        with open(os.path.join(out, "efsi-weak-00001.sbatch")) as f:
            self.assertIn("run mpirun -n 1 --map-by ppr:1:node:PE=2 --bind-to core ", f.read())

    def test_a_generated_script_runs_through_srun(self):
        """The script as a cluster would run it; `srun` here is a stand-in that starts mpirun."""
        work = scratch_for_runs(self, "efsi-srun-")
        shim = os.path.join(work, "srun")
        with open(shim, "w") as f:
            f.write("#!/bin/bash\n# Stand-in for srun: --ntasks=N becomes mpirun -n N; other srun options go.\n"
                    "n=1; while [[ $1 == --* ]]; do [[ $1 == --ntasks=* ]] && n=${1#--ntasks=}; shift; done\n"
                    f'exec {MPIEXEC} -n "$n" "$@"\n')
        os.chmod(shim, os.stat(shim).st_mode | stat.S_IXUSR)
        out = os.path.join(work, "jobs")
        r = campaign("slurm", "--out", out, "--bin-dir", os.path.abspath(BIN_DIR), "--sweep", "mini", "--ranks", "2",
                     "--configs", "acm-sync", "--cores-per-node", "2")
        self.assertEqual(r.returncode, 0, r.stderr)
        env = dict(os.environ, PATH=work + os.pathsep + os.environ.get("PATH", ""))
        job = subprocess.run(["bash", os.path.join(out, "efsi-mini-00002.sbatch")], capture_output=True, text=True,
                             env=env, timeout=300, cwd=work)
        self.assertEqual(job.returncode, 0, job.stdout + job.stderr)
        self.assertIn("--mpi=pmix", job.stdout)
        # Outside SLURM the job's CSV is named for no job, in rows/ of the directory it ran in.
        row = only_row(self, os.path.join(work, "rows", "efsi-mini-00002-nojob.csv"))
        self.assertEqual((row["experiment"], row["method"], row["ranks"], row["steps"], row["threads"], row["valid"]),
                         ("weak", "acm", "2", "2", "1", "1"))


class LocalRuns(unittest.TestCase):
    def test_dry_run_marks_oversubscription(self):
        r = campaign("local", "--sweep", "mini", "--csv", "unused.csv", "--cores", "1", "--dry-run")
        self.assertEqual(r.returncode, 0, r.stderr)
        launches = [l.strip() for l in r.stdout.splitlines() if "mpirun" in l or MPIEXEC in l]
        self.assertEqual(len(launches), 6)
        one = [l for l in launches if " -n 1 " in l]
        two = [l for l in launches if " -n 2 " in l]
        self.assertTrue(all("--oversubscribe" not in l and "--bind-to core" in l for l in one), one)
        self.assertTrue(all("--oversubscribe" in l for l in two), two)
        self.assertIn("oversubscribed", r.stdout)
        self.assertFalse(os.path.exists("unused.csv"))

    def test_local_run_appends_a_valid_row(self):
        out = os.path.join(scratch_for_runs(self, "efsi-local-"), "local.csv")
        r = campaign("local", "--sweep", "mini", "--ranks", "2", "--configs", "acm-async", "--bin-dir", BIN_DIR,
                     "--csv", out, "--launcher", MPIEXEC)
        self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
        row = only_row(self, out)
        self.assertEqual((row["experiment"], row["method"], row["comm"], row["ranks"], row["steps"], row["valid"]),
                         ("weak", "acm", "async", "2", "2", "1"))
        px, py, pz = int(row["px"]), int(row["py"]), int(row["pz"])
        self.assertEqual(px * py * pz, 2)
        self.assertEqual((int(row["nx"]) // px, int(row["ny"]) // py, int(row["nz"]) // pz), (64, 64, 64))
        self.assertGreater(float(row["elapsed_s"]), 0)


class Errors(unittest.TestCase):
    BAD = [
        ([], "the following arguments are required"),
        (["launch"], "invalid choice"),
        (["slurm"], "--out"),
        (["slurm", "--out", "{out}", "--ranks", "0"], "'0'"),
        (["slurm", "--out", "{out}", "--ranks", "3:8"], "3:8"),
        (["slurm", "--out", "{out}", "--ranks", "two"], "two"),
        (["slurm", "--out", "{out}", "--configs", "sor-sync"], "sor-sync"),
        (["slurm", "--out", "{out}", "--configs", "acm-sync-1e-3"], "acm takes no variant"),
        (["slurm", "--out", "{out}", "--configs", "mg-sync"], "mg-sync"),
        (["slurm", "--out", "{out}", "--time", "2h"], "2h"),
        (["slurm", "--out", "{out}", "--cpus-per-task", "0"], "'0'"),
        (["slurm", "--out", "{out}", "--cpus-per-task", "16"], "exceeds --cores-per-node 8"),
        (["slurm", "--out", "{out}", "--ranks-per-node", "8", "--cpus-per-task", "2"], "exceeds"),
        (["slurm", "--out", "{out}", "--account", "a b"], "a b"),
        (["slurm", "--out", "{out}", "--srun-mpi", "pmix;rm"], "pmix;rm"),
        (["slurm", "--out", "{out}", "--launcher", "aprun"], "aprun"),
        (["slurm", "--out", "{out}", "--sweep", "huge"], "huge"),
        (["slurm", "--out", "{out}", "--sweep", "strong", "--local", "32"], "does not apply"),
        (["slurm", "--out", "{out}", "--frobnicate"], "--frobnicate"),
        (["local", "--sweep", "mini"], "--csv"),
        (["local", "--sweep", "mini", "--csv", "{out}/x.csv", "--bin-dir", "/nonexistent"], "/nonexistent"),
        (["local", "--sweep", "mini", "--csv", "{out}/x.csv", "--steps", "-1"], "-1"),
        (["local", "--sweep", "mini", "--csv", "{out}/x.csv", "--launcher", "no-such-mpirun", "--bin-dir", "{bin}"],
         "no-such-mpirun"),
        (["list", "--sweep", "weak", "--what", "nodes"], "nodes"),
        (["collect", "--into", "{out}/all.csv", "{out}/missing.csv"], "missing.csv"),
    ]

    def test_one_line_and_status_2(self):
        tmp = tempfile.mkdtemp(prefix="efsi-bad-")
        self.addCleanup(shutil.rmtree, tmp, True)
        bin_dir = BIN_DIR or tmp
        for template, needle in self.BAD:
            out = os.path.join(tmp, "out")
            args = [a.replace("{out}", out).replace("{bin}", bin_dir) for a in template]
            with self.subTest(args=args):
                if "{bin}" in template and not BIN_DIR:
                    continue  # needs the drivers, so that only the launcher is wrong
                r = campaign(*args)
                self.assertEqual(r.returncode, 2, r.stdout + r.stderr)
                lines = r.stderr.splitlines()
                self.assertEqual(len(lines), 1, r.stderr)
                self.assertTrue(lines[0].startswith("campaign.py: error: "), lines[0])
                self.assertIn(needle, lines[0])
                self.assertEqual(r.stdout, "")
                self.assertFalse(os.path.exists(out), f"{args} wrote {out}")

    def test_help(self):
        for sub in ([], ["local"], ["slurm"], ["list"], ["collect"]):
            r = campaign(*sub, "--help")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("usage:", r.stdout)


class ListAndCollect(unittest.TestCase):
    def test_list(self):
        self.assertEqual(campaign("list", "--sweep", "weak", "--what", "ranks").stdout,
                         ",".join(str(2 ** k) for k in range(14)))
        self.assertEqual(campaign("list", "--sweep", "strong", "--what", "ranks").stdout, "1024,2048,4096,8192")
        self.assertEqual(campaign("list", "--sweep", "weak", "--what", "configs").stdout, ",".join(CLUSTER_CONFIGS))
        self.assertEqual(campaign("list", "--sweep", "mini", "--what", "driver").stdout, "weak_scaling")

    def test_all_methods_come_from_the_registry(self):
        """The local sweeps run every method the drivers list, in each halo mode it takes, at
        each variant; a method registered later joins them with no edit to the harness."""
        if not BIN_DIR:
            self.skipTest("no --bin-dir")
        listing = subprocess.run([os.path.join(BIN_DIR, "weak_scaling"), "--list-methods"], capture_output=True,
                                 text=True, check=True).stdout
        expected = set()
        methods = [l[len("method "):].split("|") for l in listing.splitlines() if l.startswith("method ")]
        variants = [l[len("variant "):].split("|") for l in listing.splitlines() if l.startswith("variant ")]
        self.assertGreaterEqual(len(methods), 3, listing)
        for f in methods:
            for comm in ("sync", "async") if f[5] == "async" else ("sync",):
                labels = [v[1] for v in variants if v[0] == f[0]]
                expected |= {f"{f[0]}-{comm}-{v}" for v in labels} if labels else {f"{f[0]}-{comm}"}
        self.assertIn("sor-async-1e-4", expected)
        for sweep in ("local-weak", "local-strong", "quick-weak", "quick-strong"):
            got = campaign("list", "--sweep", sweep, "--what", "configs", "--bin-dir", BIN_DIR).stdout.split(",")
            self.assertEqual(sorted(got), sorted(expected), sweep)

    def test_a_new_method_joins_the_sweeps(self):
        sys.path.insert(0, os.path.join(REPO, "harness"))
        import campaign_sweeps as cs
        methods = cs.parse_catalog("method acm|ACM|1.25e-05|50|0|async\n"
                                   "method mg|SMAC with multigrid|6.25e-05|10|20|sync\n"
                                   "variant mg|1e-3|--eps 1e-3\nvariant mg|1e-6|--eps 1e-6 --mg-iters 9\n"
                                   "option --eps|mg|tolerance\n")
        names = [c.name for c in cs.SWEEPS["local-weak"].configs(methods)]
        self.assertEqual(names, ["acm-sync", "acm-async", "mg-sync-1e-3", "mg-sync-1e-6"])
        self.assertEqual(cs.parse_config("mg-sync-1e-6", methods).driver_args(),
                         ["--method", "mg", "--comm", "sync", "--eps", "1e-6", "--mg-iters", "9"])
        for bad, needle in (("mg-async-1e-3", "no async halo mode"), ("mg-sync", "needs a variant"),
                            ("acm-sync-1e-3", "only mg"), ("sor-sync-1e-3", "METHOD in acm|mg")):
            with self.assertRaises(cs.SweepError) as e:
                cs.parse_config(bad, methods)
            self.assertIn(needle, str(e.exception))

    def test_collect_appends_under_one_header(self):
        tmp = tempfile.mkdtemp(prefix="efsi-collect-")
        self.addCleanup(shutil.rmtree, tmp, True)
        fixture = os.path.join(HERE, "data", "weak-mini.csv")
        with open(fixture) as f:
            header, *rows = f.read().splitlines()
        a, b = os.path.join(tmp, "a.csv"), os.path.join(tmp, "b.csv")
        for path, part in ((a, rows[:2]), (b, rows[2:])):
            with open(path, "w") as f:
                f.write("\n".join([header] + part) + "\n")
        into = os.path.join(tmp, "sub", "all.csv")
        self.assertEqual(campaign("collect", "--into", into, a).returncode, 0)
        self.assertEqual(campaign("collect", "--into", into, b).returncode, 0)
        with open(into) as f:
            self.assertEqual(f.read().splitlines(), [header] + rows)
        # A file with another header is refused and the target is left as it was.
        other = os.path.join(tmp, "other.csv")
        with open(other, "w") as f:
            f.write("a,b\n1,2\n")
        r = campaign("collect", "--into", into, other)
        self.assertEqual(r.returncode, 2)
        self.assertIn("header", r.stderr)
        with open(into) as f:
            self.assertEqual(f.read().splitlines(), [header] + rows)


if __name__ == "__main__":
    if "--bin-dir" in sys.argv:
        i = sys.argv.index("--bin-dir")
        BIN_DIR = sys.argv[i + 1]
        del sys.argv[i:i + 2]
    if BIN_DIR:  # campaign.py lists the methods with these drivers when --bin-dir names a cluster's
        os.environ["EFSI_BIN_DIR"] = os.path.abspath(BIN_DIR)
    unittest.main()
