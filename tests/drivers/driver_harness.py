#!/usr/bin/env python3
"""What the driver tests share: launching a built driver on 1 or more ranks (killing
hung jobs), snapshots of a directory, CSV tables, and the check of a section-8 CSV row
against the launch that wrote it (docs/architecture.md, "Programs and their command lines").

Standard library only. BIN_DIR is set by main() from --bin-dir or EFSI_BIN_DIR."""

import atexit
import csv
import datetime
import errno
import io
import math
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time
import unittest

BIN_DIR = os.environ.get("EFSI_BIN_DIR", "")
MPIEXEC = os.environ.get("EFSI_MPIEXEC") or shutil.which("mpiexec") or shutil.which("mpirun") or "mpiexec"

# Seconds a run that should finish quickly may take (generous: sanitizer builds, a busy
# machine), and how long to wait for a run that is known to hang before killing it.
RUN_TIMEOUT = 180
HANG_TIMEOUT = 10

# The exit status of a run whose outputs could not be written at the end (drivers/driver_support.hpp).
EXIT_OUTPUT_FAILED = 5

SECTION8_COLUMNS = (
    "experiment,method,comm,eps,ranks,threads,px,py,pz,nx,ny,nz,particles,steps,dt,"
    "ns_per_step,nc_per_step,elapsed_s,compute_s,halo_s,reduce_s,comm_s,comm_s_max,"
    "comm_fraction,mlups,div_rms,valid,host,mpi,compiler,git_sha,timestamp").split(",")
INT_COLUMNS = ("ranks", "threads", "px", "py", "pz", "nx", "ny", "nz", "particles", "steps", "valid")
FLOAT_COLUMNS = ("dt", "elapsed_s", "compute_s", "halo_s", "reduce_s", "comm_s", "comm_s_max",
                 "comm_fraction", "mlups", "div_rms")
# Numbers where they apply, empty where they do not (ACM has no SOR tolerance or sweeps).
OPTIONAL_NUMBER_COLUMNS = ("eps", "ns_per_step", "nc_per_step")
TEXT_COLUMNS = ("host", "mpi", "compiler", "git_sha")
# The suite's columns after section 8's: the hybrid layout (harness/hybrid_layout.hpp).
SUITE_COLUMNS = ["oversubscribed", "omp_num_threads", "omp_places", "omp_proc_bind", "cores", "integrator",
                 "pressure_iterations", "pressure_setup_s", "cores_shared",
                 "simulated", "mpi_messages_per_step", "mpi_bytes_per_step", "halo", "sweeps_per_exchange"]

class Result:
    def __init__(self, rc, out, err, timed_out, seconds):
        self.rc, self.out, self.err, self.timed_out, self.seconds = rc, out, err, timed_out, seconds

    def __str__(self):
        state = "timed out" if self.timed_out else "exit status %s" % self.rc
        return "%s after %.1f s\n--- stdout ---\n%s--- stderr ---\n%s" % (state, self.seconds, self.out, self.err)


def program_path(program="channel"):
    return os.path.join(BIN_DIR, program)


def channel_path():
    return program_path("channel")


# Open MPI's session directories under a base of this process's own (Open MPI 4.1 does not
# tolerate two launches creating TMPDIR/ompi.HOST.UID at the same moment).
SESSION_BASE = tempfile.mkdtemp(prefix="efsi_ompi_")
atexit.register(shutil.rmtree, SESSION_BASE, True)


def test_env(threads=1):
    env = dict(os.environ)
    env.setdefault("OMPI_MCA_orte_tmpdir_base", SESSION_BASE)
    env.update({
        "OMPI_ALLOW_RUN_AS_ROOT": "1",
        "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
        # Lets mpiexec start 2 ranks on a 1-core machine; the driver itself still marks
        # such runs as oversubscribed, which the CSV checks expect.
        "OMPI_MCA_rmaps_base_oversubscribe": "1",
        "OMPI_MCA_btl_vader_single_copy_mechanism": "none",
        "OMP_NUM_THREADS": str(threads),
        "ASAN_OPTIONS": env.get("ASAN_OPTIONS", "detect_leaks=0"),
    })
    return env


def kill_session(sid):
    """SIGKILL every process of session `sid` (one this file started with start_new_session:
    the launcher and the ranks it forked, whatever process group they put themselves in)."""
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % name) as f:
                stat = f.read()
        except OSError:
            continue
        fields = stat[stat.rindex(")") + 2:].split()
        if int(fields[3]) == sid:
            try:
                os.kill(int(name), signal.SIGKILL)
            except OSError:
                pass


def launch_command(args, ranks, rank_status_dir=None, program="channel"):
    """The command line for `ranks` ranks: the bare executable for 1 (an MPI singleton, as
    a user would start it), mpiexec otherwise.  With rank_status_dir, every rank runs under
    a shell that writes the rank's exit status to rank_status_dir/rank<N>."""
    prog = [program_path(program)] + list(args)
    if rank_status_dir is not None:
        prog = ["/bin/sh", "-c",
                'd=$1; shift; "$@"; rc=$?; echo "$rc" > "$d/rank${OMPI_COMM_WORLD_RANK:-${PMI_RANK:-0}}"; exit "$rc"',
                "sh", rank_status_dir] + prog
    if ranks == 1 and rank_status_dir is None:
        return prog
    return [MPIEXEC, "-q", "-n", str(ranks)] + prog


def start(args, ranks=1, cwd=None, threads=1, rank_status_dir=None, extra_env=None, program="channel"):
    env = test_env(threads)
    if extra_env:
        env.update(extra_env)
    return subprocess.Popen(launch_command(args, ranks, rank_status_dir, program), cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def finish(proc, timeout, started):
    try:
        out, err = proc.communicate(timeout=timeout)
        return Result(proc.returncode, out, err, False, time.monotonic() - started)
    except subprocess.TimeoutExpired:
        kill_session(proc.pid)
        try:
            out, err = proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()
            out, err = "", "(output lost: the launcher did not close its pipes after SIGKILL)"
        return Result(None, out or "", err or "", True, time.monotonic() - started)


def run(args, ranks=1, cwd=None, threads=1, timeout=RUN_TIMEOUT, rank_status_dir=None, extra_env=None,
        program="channel"):
    t0 = time.monotonic()
    proc = start(args, ranks, cwd, threads, rank_status_dir, extra_env, program)
    return finish(proc, timeout, t0)


def numbers_in(text):
    return [float(m) for m in re.findall(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?", text)]


def snapshot(directory):
    """Every file under `directory` with its size, modification time and content."""
    state = {}
    for root, dirs, files in os.walk(directory):
        for name in dirs + files:
            path = os.path.join(root, name)
            rel = os.path.relpath(path, directory)
            if os.path.isdir(path):
                state[rel + "/"] = None
            else:
                st = os.stat(path)
                with open(path, "rb") as f:
                    state[rel] = (st.st_size, st.st_mtime_ns, f.read())
    return state


def read_table(path):
    with open(path, newline="") as f:
        text = f.read()
    rows = list(csv.reader(io.StringIO(text)))
    return text, rows


def cpu_count():
    try:
        return os.sysconf("SC_NPROCESSORS_ONLN")
    except (ValueError, OSError):
        return os.cpu_count() or 1


class DriverTestCase(unittest.TestCase):
    program = "channel"

    def setUp(self):
        if not os.access(program_path(self.program), os.X_OK):
            self.fail("no %s executable at %r: pass --bin-dir or set EFSI_BIN_DIR"
                      % (self.program, program_path(self.program)))
        self.dir = tempfile.mkdtemp(prefix="efsi_%s_cli_" % self.program)
        self.addCleanup(shutil.rmtree, self.dir, True)
        self.started = datetime.datetime.now(datetime.timezone.utc)

    def path(self, name):
        return os.path.join(self.dir, name)

    def run_on_two_ranks(self, args, timeout=RUN_TIMEOUT, extra_env=None):
        """Runs with every rank's exit status recorded; mpiexec is told not to abort the job
        when the first rank exits, so that each rank reports its own status."""
        status_dir = tempfile.mkdtemp(prefix="efsi_rank_status_")
        self.addCleanup(shutil.rmtree, status_dir, True)
        env = {"OMPI_MCA_orte_abort_on_non_zero_status": "0", "OMPI_MCA_prte_abort_on_non_zero_status": "0"}
        env.update(extra_env or {})
        res = run(args, ranks=2, cwd=self.dir, timeout=timeout, rank_status_dir=status_dir, extra_env=env,
                  program=self.program)
        statuses = {}
        for name in sorted(os.listdir(status_dir)):
            with open(os.path.join(status_dir, name)) as f:
                statuses[name] = f.read().strip()
        return res, statuses

    def small_tmpfs(self, full=False):
        """A 64 KiB tmpfs mounted for this test (unmounted in its cleanup), filled up to the
        last byte with `full`; skips the test where mounting is not permitted."""
        if os.geteuid() != 0:
            self.skipTest("mounting a 64 KiB tmpfs needs root")
        mnt = tempfile.mkdtemp(prefix="efsi_tmpfs_")
        self.addCleanup(os.rmdir, mnt)
        res = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", mnt], capture_output=True, text=True)
        if res.returncode != 0:
            self.skipTest("cannot mount a tmpfs: %s" % res.stderr.strip())
        self.addCleanup(subprocess.run, ["umount", mnt], check=True)
        if full:
            self.fill(mnt)
        return mnt

    @staticmethod
    def fill(directory):
        """Fills the file system of `directory` with a file named "filler"."""
        with open(os.path.join(directory, "filler"), "wb", buffering=0) as f:
            try:
                while True:
                    f.write(b"\0" * 4096)
            except OSError as e:
                if e.errno != errno.ENOSPC:
                    raise

    def fake_node(self, available_kb):
        """The environment that makes the drivers read a /proc/meminfo of `available_kb`
        kB MemAvailable (None: no such line) (EFSI_MEMINFO, test-only), from a file outside
        self.dir."""
        d = tempfile.mkdtemp(prefix="efsi_meminfo_")
        self.addCleanup(shutil.rmtree, d, True)
        path = os.path.join(d, "meminfo")
        with open(path, "w") as f:
            f.write("MemTotal:        2000000 kB\nMemFree:         1500000 kB\n")
            if available_kb is not None:
                f.write("MemAvailable:    %8d kB\n" % available_kb)
            f.write("Buffers:           10000 kB\n")
        return {"EFSI_MEMINFO": path}

    def check_memory_refusal(self, res, ranks=1, statuses=None):
        """Exit status 2 (of every rank, with the `statuses` of run_on_two_ranks) and one
        stderr line naming what the node needs and has, in GiB, and --force-memory; returns
        (needed, per rank, available) in GiB."""
        self.assertFalse(res.timed_out, str(res))
        if statuses is None:
            self.assertEqual(res.rc, 2, str(res))
        else:
            self.assertEqual(statuses, {"rank%d" % r: "2" for r in range(ranks)},
                             "every rank must exit with status 2:\n%s" % res)
        lines = res.err.splitlines()
        self.assertEqual(len(lines), 1, "expected one line on stderr:\n%s" % res)
        m = re.fullmatch(r"%s: error: the run needs (\S+) GiB on this node \(%d ranks? x (\S+) GiB, estimated\) "
                         r"but (\S+) GiB are available \(MemAvailable\); --force-memory runs it anyway"
                         % (self.program, ranks), lines[0])
        self.assertIsNotNone(m, lines[0])
        need, per_rank, available = (float(x) for x in m.groups())
        self.assertAlmostEqual(need, ranks * per_rank, delta=0.01 * need)
        self.assertGreater(need, available)
        return need, per_rank, available

    def run_ok(self, args, ranks=1, threads=1, **kw):
        res = run(args, ranks=ranks, cwd=self.dir, threads=threads, program=self.program, **kw)
        self.assertFalse(res.timed_out, "%s %s on %d rank(s) hung:\n%s" % (self.program, " ".join(args), ranks, res))
        self.assertEqual(res.rc, 0, "%s %s on %d rank(s):\n%s" % (self.program, " ".join(args), ranks, res))
        return res

    # ---- the CSV run record ----

    def check_header(self, header):
        self.assertEqual(header[:len(SECTION8_COLUMNS)], SECTION8_COLUMNS,
                         "the CSV header must begin with the columns of docs/numerics.md, 'Output: the CSV run record', in order")
        self.assertEqual(len(set(header)), len(header), "repeated column in %s" % header)
        self.assertEqual(header[len(SECTION8_COLUMNS):], SUITE_COLUMNS, "the suite's own columns follow")

    def check_row(self, header, row, ranks, threads, cells, steps, particles, comm, dims=None,
                  experiment="channel", method="acm", dt=1.25e-5, div_rms_max=1e-8, integrator="euler"):
        """One CSV row against the launch that wrote it; returns it as a dict of values."""
        self.assertEqual(len(row), len(header), "row %s does not match the header %s" % (row, header))
        r = dict(zip(header, row))
        v = {}
        for c in INT_COLUMNS:
            try:
                v[c] = int(r[c])
            except ValueError:
                self.fail("column %s = %r is not an integer (row %s)" % (c, r[c], row))
        for c in FLOAT_COLUMNS:
            try:
                v[c] = float(r[c])
            except ValueError:
                self.fail("column %s = %r is not a number (row %s)" % (c, r[c], row))
            self.assertTrue(math.isfinite(v[c]), "column %s = %r is not finite" % (c, r[c]))
        for c in OPTIONAL_NUMBER_COLUMNS:
            if r[c] != "":
                try:
                    float(r[c])
                except ValueError:
                    self.fail("column %s = %r is neither empty nor a number" % (c, r[c]))
        for c in TEXT_COLUMNS:
            self.assertTrue(r[c].strip(), "column %s is empty" % c)
        self.assertEqual(r["experiment"], experiment)
        self.assertEqual(r["method"], method)
        self.assertEqual(r["comm"], comm)
        self.assertEqual(r["host"], socket.gethostname())
        self.assertIn("MPI", r["mpi"])

        # The launch.
        self.assertEqual(v["ranks"], ranks)
        self.assertEqual(v["threads"], threads)
        self.assertEqual(v["px"] * v["py"] * v["pz"], ranks)
        if dims is not None:
            self.assertEqual((v["px"], v["py"], v["pz"]), dims)
        for c, n in zip(("nx", "ny", "nz"), cells):
            self.assertEqual(v[c], n)
        for c, p in (("nx", "px"), ("ny", "py"), ("nz", "pz")):
            self.assertEqual(v[c] % v[p], 0, "%s=%d is not a multiple of %s=%d" % (c, v[c], p, v[p]))
        self.assertEqual(v["particles"], particles)
        self.assertEqual(v["steps"], steps)
        self.assertAlmostEqual(v["dt"], dt, delta=1e-15)

        # The numbers against each other.
        oversubscribed = ranks * threads > cpu_count()
        self.assertEqual(int(r["oversubscribed"]), 1 if oversubscribed else 0)
        self.assertEqual(v["valid"], 0 if oversubscribed else 1, "the run's own checks must pass: %s" % r)
        self.assertGreater(v["elapsed_s"], 0)
        for c in ("compute_s", "halo_s", "reduce_s", "comm_s", "comm_s_max", "div_rms"):
            self.assertGreaterEqual(v[c], 0, c)
        self.assertGreater(v["compute_s"], 0)
        self.assertGreaterEqual(v["comm_s_max"], v["comm_s"] * (1 - 1e-8))
        self.assertLessEqual(v["reduce_s"], v["comm_s"] * (1 + 1e-8) + 1e-12,
                             "comm_s is halo MPI plus reductions, so at least reduce_s")
        self.assertGreaterEqual(v["comm_fraction"], 0)
        self.assertLessEqual(v["comm_fraction"], 1)
        self.assertAlmostEqual(v["comm_fraction"], v["comm_s"] / v["elapsed_s"],
                               delta=1e-6 * max(1.0, v["comm_fraction"]))
        self.assertGreater(v["mlups"], 0)
        expected_mlups = cells[0] * cells[1] * cells[2] * steps / v["elapsed_s"] / 1e6
        self.assertAlmostEqual(v["mlups"], expected_mlups, delta=1e-6 * expected_mlups)
        self.assertLess(v["div_rms"], div_rms_max, "a few steps from rest keep the velocity divergence-free")
        self.assertEqual(r["integrator"], integrator)
        # The iterative methods' mean iterations per solve: N_S for SOR, V-cycles for mg.
        if method == "sor" and r["ns_per_step"]:
            self.assertAlmostEqual(float(r["pressure_iterations"]), float(r["ns_per_step"]))
        elif method == "mg":
            self.assertGreaterEqual(float(r["pressure_iterations"]), 1.0)
        elif method in ("acm", "fft"):
            self.assertEqual(r["pressure_iterations"], "")
        self.assertGreaterEqual(float(r["pressure_setup_s"]), 0.0)
        # The hybrid layout: the environment the ranks saw, one core list per rank.
        self.assertEqual(r["omp_num_threads"], str(threads))
        # The distinct bindings with their rank counts: a size that does not grow with the ranks.
        bindings = [b.split("*") for b in r["cores"].split("/")]
        for cores, count in bindings:
            self.assertRegex(cores, r"^\d+(-\d+)?(\+\d+(-\d+)?)*$", r["cores"])
        self.assertEqual(len({cores for cores, _ in bindings}), len(bindings), r["cores"])
        self.assertEqual(sum(int(count) for _, count in bindings), ranks, "every rank counted once: %r" % r["cores"])
        self.assertIn(r["cores_shared"], ("0", "1"))

        # Timing the measured steps only: every region a rank times lies inside its own
        # measured steps, so the means of the regions add up to no more than the slowest
        # rank's elapsed time.
        self.assert_regions_inside_elapsed(v)

        stamp = datetime.datetime.strptime(r["timestamp"], "%Y-%m-%dT%H:%M:%SZ").replace(
            tzinfo=datetime.timezone.utc)
        now = datetime.datetime.now(datetime.timezone.utc)
        slack = datetime.timedelta(seconds=120)
        self.assertTrue(self.started - slack <= stamp <= now + slack,
                        "timestamp %s is not the time of the run (UTC)" % r["timestamp"])
        return v

    def assert_regions_inside_elapsed(self, v):
        regions = v["compute_s"] + v["halo_s"] + v["reduce_s"]
        self.assertLessEqual(regions, v["elapsed_s"] * 1.02 + 1e-4,
                             "compute_s + halo_s + reduce_s = %.6g exceeds elapsed_s = %.6g: time outside "
                             "the measured steps was counted" % (regions, v["elapsed_s"]))


def main():
    global BIN_DIR
    argv = list(sys.argv)
    if "--bin-dir" in argv:
        i = argv.index("--bin-dir")
        BIN_DIR = argv[i + 1]
        del argv[i:i + 2]
    if not BIN_DIR:
        sys.exit("%s: give the build's bin directory with --bin-dir DIR or EFSI_BIN_DIR" % os.path.basename(argv[0]))
    BIN_DIR = os.path.abspath(BIN_DIR)  # the runs start in temporary directories
    unittest.main(argv=argv, verbosity=2)

