#!/usr/bin/env python3
"""The campaign under a real SLURM: the one-node cluster of harness/slurm-local, end to end.

Starts munged, slurmctld and slurmd (harness/slurm-local/local_cluster.py) in a scratch
directory, then
- writes the mini sweep with `campaign.py slurm` (1 and 2 ranks, flat) and its hybrid variant
  (1 rank, --cpus-per-task 2), submits both with their submit_all.sh, waits for the jobs
  through squeue and checks with scontrol that each one COMPLETED with exit code 0;
- gathers the jobs' CSVs with `campaign.py collect` and checks every row: valid, not
  oversubscribed, the rank and thread counts of its job, the OpenMP settings of the script,
  and a `cores` column that is the binding SLURM gave (flat: each rank its own core; hybrid:
  the rank both cores), as distinct bindings with their rank counts, none shared;
- runs one ReFrame check (weak_scaling with ACM) on the `slurm` partition of dev-2core
  through harness/reframe/run.sh, without references (no test here judges timings), and
  checks from its report that it passed as a SLURM job with its three figures;
- stops every daemon by its pid, on every exit path, and checks that none is left.

A cluster that cannot start (not root, packages missing, a port taken) is one line on
stderr and exit status 1.  Nothing waits without a limit: every command has a timeout.  If
this process is killed outright (CTest's timeout), the daemons die with it and a watcher
outside its process tree stops the job steps left and removes the scratch directory.

Usage: test_slurm_local.py --bin-dir BUILD/bin [unittest options]
"""

import csv
import glob
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
CAMPAIGN = os.path.join(REPO, "harness", "campaign.py")
REFRAME_RUN = os.path.join(REPO, "harness", "reframe", "run.sh")
sys.path.insert(0, os.path.join(REPO, "harness", "slurm-local"))
import local_cluster  # noqa: E402

PROG = "test_slurm_local"
JOB_WAIT_S = 300       # the mini sweep and its hybrid variant take about half a minute here
REFRAME_WAIT_S = 300   # includes creating the venv when it is missing


class Context:
    """What the tests share: the running cluster and the scratch directory."""
    cluster = None
    work = None
    bin_dir = ""


def slurm(*cmd, timeout=30):
    return subprocess.run(list(cmd), capture_output=True, text=True, env=Context.cluster.env, timeout=timeout)


def core_set(text):
    """'0-2+5' -> {0, 1, 2, 5}"""
    out = set()
    for part in text.split("+"):
        lo, _, hi = part.partition("-")
        out |= set(range(int(lo), int(hi or lo) + 1))
    return out


def wait_for_jobs(ids, limit):
    end = time.monotonic() + limit
    while time.monotonic() < end:
        left = slurm("squeue", "-h", "-j", ",".join(ids), "-o", "%i").stdout.split()
        if not left:
            return
        time.sleep(1)
    raise AssertionError(f"jobs {', '.join(ids)} still queued or running after {limit} s")


def job_fields(job_id):
    text = slurm("scontrol", "show", "job", job_id).stdout
    return dict(re.findall(r"([\w/:]+)=(\S*)", text))


class CampaignUnderSlurm(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.env = dict(Context.cluster.env, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
        cls.node_cpus = int(job_fields_node()["CPUTot"])
        cls.jobs = {}  # job id -> (script, ranks, threads, campaign directory)
        for kind, extra in (("flat", []), ("hybrid", ["--ranks", "1", "--cpus-per-task", "2", "--job-prefix", "efsi-hybrid"])):
            out = os.path.join(Context.work, kind)
            r = subprocess.run([sys.executable, CAMPAIGN, "slurm", "--sweep", "mini", "--out", out, "--bin-dir",
                                Context.bin_dir, "--cores-per-node", str(cls.node_cpus), *extra],
                               capture_output=True, text=True, timeout=60)
            assert r.returncode == 0, r.stderr
            sub = subprocess.run(["bash", os.path.join(out, "submit_all.sh")], capture_output=True, text=True,
                                 env=cls.env, cwd=Context.work, timeout=60)
            assert sub.returncode == 0, sub.stdout + sub.stderr
            with open(os.path.join(out, "manifest.csv")) as f:
                manifest = {m["script"]: m for m in csv.DictReader(f)}
            with open(os.path.join(out, "submitted.txt")) as f:
                for line in f:
                    job_id, script = line.split()
                    m = manifest[script]
                    cls.jobs[job_id] = (script, int(m["ranks"]), int(m["cpus_per_task"]), out)
        wait_for_jobs(list(cls.jobs), JOB_WAIT_S)
        cls.collected = os.path.join(Context.work, "all.csv")
        parts = sorted(glob.glob(os.path.join(Context.work, "*", "rows", "*.csv")))
        cls.collect = subprocess.run([sys.executable, CAMPAIGN, "collect", "--into", cls.collected, *parts],
                                     capture_output=True, text=True, timeout=60)
        cls.parts = parts

    def test_every_job_completed(self):
        self.assertEqual(len(self.jobs), 3, self.jobs)  # flat 1 and 2 ranks, hybrid 1 rank
        for job_id, (script, ranks, threads, out) in self.jobs.items():
            with self.subTest(job=job_id, script=script):
                with open(os.path.join(out, f"{script[:-7]}-{job_id}.out")) as log:
                    text = log.read()
                f = job_fields(job_id)
                self.assertEqual((f.get("JobState"), f.get("ExitCode")), ("COMPLETED", "0:0"), text[-3000:])
                self.assertEqual((int(f["NumTasks"]), int(f["CPUs/Task"])), (ranks, threads))
                self.assertEqual(text.count("+ srun --mpi=pmix "), 3, text)  # acm-sync, sor-async-1e-3, mg-sync-1e-3
                self.assertEqual(len(re.findall(r"(?m)^validation: .*: PASSED$", text)), 3, text)

    def test_one_csv_per_job_gathered_by_collect(self):
        self.assertEqual(self.collect.returncode, 0, self.collect.stderr)
        names = sorted(os.path.basename(p) for p in self.parts)
        expected = sorted(f"{script[:-7]}-{job_id}.csv" for job_id, (script, *_rest) in self.jobs.items())
        self.assertEqual(names, expected)
        self.assertIn(f"collected 9 row(s) into {self.collected}", self.collect.stdout)

    def test_rows_show_ranks_threads_and_the_binding_slurm_gave(self):
        with open(self.collected) as f:
            rows = list(csv.DictReader(f))
        self.assertEqual(len(rows), 9)
        got = sorted((r["ranks"], r["threads"], r["method"], r["comm"]) for r in rows)
        self.assertEqual(got, sorted([(n, t, m, c) for n, t in (("1", "1"), ("2", "1"), ("1", "2"))
                                      for m, c in (("acm", "sync"), ("sor", "async"), ("mg", "sync"))]))
        all_cores = set(range(self.node_cpus))
        for r in rows:
            with self.subTest(ranks=r["ranks"], threads=r["threads"], method=r["method"]):
                ranks, threads = int(r["ranks"]), int(r["threads"])
                self.assertEqual((r["valid"], r["oversubscribed"], r["experiment"], r["steps"]), ("1", "0", "weak", "2"))
                self.assertEqual((r["omp_num_threads"], r["omp_places"], r["omp_proc_bind"]),
                                 (str(threads), "cores", "close"))
                self.assertEqual(int(r["px"]) * int(r["py"]) * int(r["pz"]), ranks)
                self.assertEqual(r["host"], Context.cluster.node)
                # --cpu-bind=cores: each rank exactly its own cores, so every binding is one
                # rank's and no two overlap.
                bindings = [b.split("*") for b in r["cores"].split("/")]
                self.assertEqual([count for _, count in bindings], ["1"] * ranks, r["cores"])
                per_rank = [core_set(c) for c, _ in bindings]
                for cores in per_rank:
                    self.assertEqual(len(cores), threads, r["cores"])
                    self.assertLessEqual(cores, all_cores, r["cores"])
                self.assertEqual(len(set.union(*per_rank)), ranks * threads, f"ranks share cores: {r['cores']}")
                self.assertEqual(r["cores_shared"], "0", r["cores"])

    def test_reframe_check_through_slurm(self):
        out = os.path.join(Context.work, "reframe")
        env = dict(self.env, EFSI_REFRAME_OUT=out, EFSI_BIN_DIR=Context.bin_dir, RFM_COLORIZE="n")
        r = subprocess.run(["bash", REFRAME_RUN, "slurm", "-n", "weak_scaling-acm", "-S", "use_references=false"],
                           capture_output=True, text=True, env=env, timeout=REFRAME_WAIT_S)
        self.assertEqual(r.returncode, 0, r.stdout[-3000:] + r.stderr[-2000:])
        self.assertRegex(r.stdout, r"\[\s+PASSED\s+\] Ran 1/1 test case")
        with open(os.path.join(out, "report-slurm.json")) as f:
            report = json.load(f)
        cases = [c for run in report["runs"] for c in run["testcases"]]
        self.assertEqual(len(cases), 1)
        case = cases[0]
        self.assertEqual((case["result"], case["system"], case["partition"], case["scheduler"]),
                         ("pass", "dev-2core", "slurm", "squeue"))
        self.assertEqual(job_fields(str(case["jobid"])).get("JobState"), "COMPLETED")
        # perfvalues: {"SYSTEM:PARTITION:VAR": [value, reference, lower, upper, unit, result]}
        figures = {k.rsplit(":", 1)[1]: v[0] for k, v in case["perfvalues"].items()}
        self.assertEqual({v[1] for v in case["perfvalues"].values()}, {0}, "a reference was applied")
        self.assertEqual(sorted(figures), ["comm_fraction", "elapsed", "mlups"])
        self.assertGreater(figures["elapsed"], 0)
        self.assertGreater(figures["mlups"], 0)
        self.assertTrue(0 <= figures["comm_fraction"] < 1, figures)


def job_fields_node():
    text = slurm("scontrol", "show", "node", Context.cluster.node).stdout
    return dict(re.findall(r"([\w/:]+)=(\S*)", text))


def main(argv):
    if "--bin-dir" in argv:
        i = argv.index("--bin-dir")
        Context.bin_dir = os.path.abspath(argv[i + 1])
        del argv[i:i + 2]
    if not Context.bin_dir:
        print(f"{PROG}: error: give --bin-dir BUILD/bin", file=sys.stderr)
        return 2
    # CTest ends a test that runs too long with a signal: the finally below still runs.
    for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(sig, lambda s, _f: sys.exit(128 + s))
    Context.work = tempfile.mkdtemp(prefix="efsi-slurm-test-")
    os.chmod(Context.work, 0o755)  # munged: every directory above its socket searchable by all
    cluster = local_cluster.LocalCluster(os.path.join(Context.work, "cluster"), die_with_parent=True)
    ok = False
    try:
        try:
            cluster.start(timeout=60)
        except local_cluster.ClusterError as e:
            print(f"{PROG}: the local SLURM cluster did not start: {e}", file=sys.stderr)
            return 1
        Context.cluster = cluster
        cluster.watch(os.getpid(), remove=Context.work)  # for a SIGKILL, which skips the finally
        ok = unittest.main(argv=[PROG] + argv[1:], exit=False).result.wasSuccessful()
    finally:
        started = dict(cluster.pids)
        try:
            cluster.stop()
        except local_cluster.ClusterError as e:
            print(f"{PROG}: {e}", file=sys.stderr)
            ok = False
        left = [f"{n} {p}" for n, p in started.items() if local_cluster.alive(p)] + \
               [f"job step {p}" for p in cluster.strays()]
        if left:
            print(f"{PROG}: daemons still running after stop: {', '.join(left)}", file=sys.stderr)
            ok = False
        elif started:
            print(f"{PROG}: stopped {', '.join(f'{n} {p}' for n, p in started.items())}")
        shutil.rmtree(Context.work, True)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
