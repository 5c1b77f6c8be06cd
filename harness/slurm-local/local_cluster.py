#!/usr/bin/env python3
"""A one-node SLURM cluster on this machine, from Debian's packages, with no init system.

  local_cluster.py install                 apt-get the missing slurmctld, slurmd, slurm-client, munge
  local_cluster.py start  [--dir DIR]      write slurm.conf and a munge key, start the daemons,
                                           wait until the node is idle
  local_cluster.py env    [--dir DIR]      the `export SLURM_CONF=...` line for a shell
  local_cluster.py status [--dir DIR]      which daemons run, and sinfo
  local_cluster.py stop   [--dir DIR]      cancel the jobs, stop the daemons by their process ids

Everything lives under DIR (default /tmp/efsi-slurm): its own munge key and socket, so a
munged already running here is left alone; state, spool, logs and the process ids of the
daemons (DIR/pids.json).  Ports are free ones picked at start unless --ports says which.
harness/CAMPAIGN.md describes the configuration and why each plugin was chosen.  Standard
library only; importable (tests/tools/test_slurm_local.py starts and stops it from Python).
"""

import argparse
import ctypes
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time

PROG = "local_cluster.py"
DEFAULT_DIR = "/tmp/efsi-slurm"
PACKAGES = ("slurmctld", "slurmd", "slurm-client", "munge")
PARTITION = "local"
DAEMONS = ("munged", "slurmctld", "slurmd")  # start order; stopped in reverse


class ClusterError(Exception):
    """Why the cluster could not start or stop, in one line."""


def missing_packages():
    missing = []
    for p in PACKAGES:
        r = subprocess.run(["dpkg-query", "-W", "-f=${Status}", p], capture_output=True, text=True)
        if "install ok installed" not in r.stdout:
            missing.append(p)
    return missing


def install():
    """Installs the missing packages; recommends are skipped (they pull in every plugin's -dev)."""
    missing = missing_packages()
    if not missing:
        print("slurmctld, slurmd, slurm-client and munge are installed")
        return
    sudo = [] if os.geteuid() == 0 else ["sudo"]
    # Debian containers ship a policy-rc.d that keeps the packages from starting their
    # services; without it they would try to, and there is no init system to do it.
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    print(f"installing: {' '.join(missing)}", flush=True)
    for cmd in (["apt-get", "update", "-qq"], ["apt-get", "install", "-y", "-qq", "--no-install-recommends", *missing]):
        r = subprocess.run(sudo + cmd, env=env)
        if r.returncode != 0:
            raise ClusterError(f"'{' '.join(sudo + cmd)}' failed with status {r.returncode}")


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def port_is_free(port):
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind(("0.0.0.0", port))
            return True
        except OSError:
            return False


def alive(pid):
    """True while the process exists and is not a zombie."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            state = f.read().rsplit(")", 1)[1].split()[0]
        return state != "Z"
    except (OSError, IndexError):
        return False


def reap(pid):
    try:
        os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        pass


def process_name(pid):
    try:
        with open(f"/proc/{pid}/comm") as f:
            return f.read().strip()
    except OSError:
        return ""


def terminate(pids, grace):
    """SIGTERM, then SIGKILL after `grace` seconds; the pids still alive after both."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        for pid in pids:
            try:
                os.kill(pid, sig)
            except ProcessLookupError:
                pass
        end = time.monotonic() + grace
        while time.monotonic() < end:
            for pid in pids:
                reap(pid)
            pids = [p for p in pids if alive(p)]
            if not pids:
                return []
            time.sleep(0.1)
    return pids


def _die_with_parent():
    # Linux PR_SET_PDEATHSIG: a test that is killed (a CTest timeout sends SIGKILL, which no
    # finally block survives) still takes its daemons with it.
    ctypes.CDLL(None, use_errno=True).prctl(1, signal.SIGTERM)


class LocalCluster:
    def __init__(self, directory=DEFAULT_DIR, ports=None, task_plugin="affinity", die_with_parent=False):
        self.dir = os.path.abspath(directory)
        self.conf = os.path.join(self.dir, "slurm.conf")
        self.pid_file = os.path.join(self.dir, "pids.json")
        self.socket = os.path.join(self.dir, "munge", "munge.socket")
        self.node = socket.gethostname().split(".")[0]
        self.ports = ports
        self.task_plugin = task_plugin
        self.die_with_parent = die_with_parent
        self.pids = self._read_pids()

    # --- helpers -------------------------------------------------------------------------

    @property
    def env(self):
        """The environment for SLURM commands: every one of them must see this slurm.conf."""
        return dict(os.environ, SLURM_CONF=self.conf)

    def _read_pids(self):
        try:
            with open(self.pid_file) as f:
                return {k: int(v) for k, v in json.load(f).items()}
        except (OSError, ValueError):
            return {}

    def _write_pids(self):
        with open(self.pid_file + ".tmp", "w") as f:
            json.dump(self.pids, f)
        os.replace(self.pid_file + ".tmp", self.pid_file)

    def slurm(self, *cmd, timeout=20):
        return subprocess.run(list(cmd), capture_output=True, text=True, env=self.env, timeout=timeout)

    def running(self):
        return {name: pid for name, pid in self.pids.items() if alive(pid) and process_name(pid) == name[:15]}

    def _last_error(self, name):
        """The last line of a daemon's log that says what went wrong."""
        try:
            with open(os.path.join(self.dir, "log", f"{name}.out"), errors="replace") as f:
                lines = [l.strip() for l in f if l.strip()]
        except OSError:
            return "no log"
        bad = [l for l in lines if re.search(r"error|fatal|cannot|unable", l, re.I)]
        return (bad or lines or ["empty log"])[-1]

    # --- configuration -------------------------------------------------------------------

    def _node_line(self):
        """This node's real CPUs, sockets, cores, threads and memory, as slurmd itself sees them."""
        r = subprocess.run(["slurmd", "-C"], capture_output=True, text=True, timeout=20)
        line = r.stdout.splitlines()[0] if r.returncode == 0 and r.stdout else ""
        if not line.startswith("NodeName="):
            raise ClusterError(f"'slurmd -C' did not describe this node: {(r.stdout + r.stderr).strip()[:200]}")
        hardware = line.split(None, 1)[1]
        return f"NodeName={self.node} NodeAddr=127.0.0.1 {hardware} State=UNKNOWN"

    def write_config(self, ctld_port, slurmd_port):
        d = self.dir
        text = f"""\
# One-node cluster written by harness/slurm-local/local_cluster.py; harness/CAMPAIGN.md says why.
ClusterName=efsi-local
SlurmctldHost={self.node}(127.0.0.1)
SlurmctldPort={ctld_port}
SlurmdPort={slurmd_port}
SlurmUser=root
SlurmdUser=root
# Our own munged on our own socket and key, so a system munged (if any) is left alone.
AuthType=auth/munge
AuthInfo=socket={self.socket}
CredType=cred/munge
StateSaveLocation={d}/state
SlurmdSpoolDir={d}/spool
SlurmctldPidFile={d}/slurmctld.pid
SlurmdPidFile={d}/slurmd.pid
SlurmctldLogFile={d}/log/slurmctld.log
SlurmdLogFile={d}/log/slurmd.log
# No cgroups in a VM or container: processes are tracked through /proc, tasks pinned with
# sched_setaffinity.
ProctrackType=proctrack/linuxproc
TaskPlugin=task/{self.task_plugin}
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
# No slurmdbd: no accounting, so sacct has nothing; finished jobs stay in scontrol for MinJobAge.
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
MinJobAge=600
MpiDefault=none
ReturnToService=2
SlurmdTimeout=300
InactiveLimit=0
{self._node_line()}
PartitionName={PARTITION} Nodes={self.node} Default=YES MaxTime=INFINITE State=UP
"""
        with open(self.conf, "w") as f:
            f.write(text)

    # --- start and stop ------------------------------------------------------------------

    def _spawn(self, name, cmd):
        log = open(os.path.join(self.dir, "log", f"{name}.out"), "ab")
        try:
            p = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=log, stderr=subprocess.STDOUT, env=self.env,
                                 cwd=self.dir, start_new_session=True,
                                 preexec_fn=_die_with_parent if self.die_with_parent else None)
        finally:
            log.close()
        self.pids[name] = p.pid
        self._write_pids()
        return p

    def _wait(self, name, what, ready, deadline):
        while time.monotonic() < deadline:
            if not alive(self.pids[name]):
                reap(self.pids[name])
                raise ClusterError(f"{name} exited while starting: {self._last_error(name)}")
            if ready():
                return
            time.sleep(0.2)
        raise ClusterError(f"{name} not {what} after the start timeout: {self._last_error(name)}")

    def start(self, timeout=60):
        """Starts munged, slurmctld and slurmd; stops whatever it started if any step fails."""
        if os.geteuid() != 0:
            raise ClusterError("starting the cluster needs root (slurmd starts job steps as their owners)")
        for exe in ("munged", "slurmctld", "slurmd", "sinfo", "sbatch"):
            if not shutil.which(exe):
                raise ClusterError(f"{exe} not found: run '{PROG} install' (Debian: {' '.join(PACKAGES)})")
        if self.running():
            raise ClusterError(f"a cluster from {self.dir} is running (pids {self.running()}): stop it first")
        ports = self.ports or (free_port(), free_port())
        for port in ports:
            if not port_is_free(port):
                raise ClusterError(f"port {port} is taken (give free ones with --ports CTLD,SLURMD)")
        if ports[0] == ports[1]:
            raise ClusterError(f"slurmctld and slurmd need two different ports, not {ports[0]} twice")
        parent = os.path.dirname(self.dir)
        while not os.path.exists(parent):
            parent = os.path.dirname(parent)
        for up in [parent] + [p for p in self._ancestors(parent)]:
            if not os.stat(up).st_mode & 0o001:
                raise ClusterError(f"{up} is not searchable by all (chmod o+x): munged needs that on every "
                                   "directory above its socket")
        deadline = time.monotonic() + timeout
        # munged wants its socket's directory open to all and its key private.
        for sub, mode in (("", 0o755), ("munge", 0o755), ("key", 0o700), ("state", 0o700), ("spool", 0o755),
                          ("log", 0o755)):
            os.makedirs(os.path.join(self.dir, sub), exist_ok=True)
            os.chmod(os.path.join(self.dir, sub), mode)
        key = os.path.join(self.dir, "key", "munge.key")
        with open(os.open(key, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600), "wb") as f:
            f.write(os.urandom(128))  # what mungekey -c writes: 1024 random bits
        self.pids = {}
        try:
            self.write_config(*ports)
            m = self.dir + "/munge"
            self._spawn("munged", ["munged", "--foreground", f"--socket={self.socket}", f"--key-file={key}",
                                   f"--log-file={m}/munged.log", f"--pid-file={m}/munged.pid",
                                   f"--seed-file={m}/munged.seed"])
            self._wait("munged", "listening", lambda: os.path.exists(self.socket), deadline)
            # -c: a fresh cluster every start, no jobs recovered from an older one in DIR.
            self._spawn("slurmctld", ["slurmctld", "-D", "-c", "-f", self.conf])
            self._wait("slurmctld", "answering", lambda: "UP" in self.slurm("scontrol", "ping").stdout, deadline)
            self._spawn("slurmd", ["slurmd", "-D", "-N", self.node, "-f", self.conf])
            self._wait("slurmd", "idle", lambda: self.node_state() == "idle", deadline)
        except BaseException:
            self.stop()
            raise
        return self

    @staticmethod
    def _ancestors(path):
        while path != os.path.dirname(path):
            path = os.path.dirname(path)
            yield path

    def node_state(self):
        try:
            r = self.slurm("sinfo", "-h", "-N", "-n", self.node, "-o", "%T", timeout=10)
        except subprocess.TimeoutExpired:
            return ""
        return r.stdout.strip()

    def strays(self):
        """Job steps of this cluster and what they started: slurmstepd processes with a file of
        DIR open (slurmd's log; they overwrite their own environment with the process title),
        then their descendants (the job scripts, srun, the drivers), which outlive a slurmd
        that was killed."""
        parents, steps = {}, []
        for entry in os.listdir("/proc"):
            if not entry.isdigit():
                continue
            pid = int(entry)
            try:
                with open(f"/proc/{pid}/stat") as f:
                    parents[pid] = int(f.read().rsplit(")", 1)[1].split()[1])
                if process_name(pid) == "slurmstepd" and alive(pid):
                    fds = os.listdir(f"/proc/{pid}/fd")
                    if any(os.readlink(f"/proc/{pid}/fd/{fd}").startswith(self.dir + "/") for fd in fds):
                        steps.append(pid)
            except (OSError, IndexError, ValueError):
                pass
        found, todo = [], list(steps)
        while todo:
            pid = todo.pop()
            if pid not in found:
                found.append(pid)
                todo += [c for c, p in parents.items() if p == pid and alive(c)]
        return found

    def watch(self, pid, remove=None, poll=0.5):
        """Stops the cluster (and removes `remove`) once process `pid` is gone, unless it was
        stopped first.  For a test that may be SIGKILLed: CTest kills a test that runs too
        long with its process tree, and a job step in flight outlives the daemons."""
        child = os.fork()
        if child:
            os.waitpid(child, 0)  # it exits at once, leaving the watcher outside our process tree
            return
        os.setsid()
        if os.fork():
            os._exit(0)
        # Not the caller's output: whoever reads it (CTest) would wait for the watcher too.
        null = os.open(os.devnull, os.O_RDWR)
        for fd in (0, 1, 2):
            os.dup2(null, fd)
        try:
            while alive(pid) and os.path.exists(self.pid_file):
                time.sleep(poll)
            if os.path.exists(self.pid_file) or self.strays():
                self.stop()
            if remove and not alive(pid):
                shutil.rmtree(remove, True)
        finally:
            os._exit(0)

    def stop(self, grace=10):
        """Cancels the jobs, then stops slurmd, the job steps left, slurmctld and munged by pid."""
        running = self.running()
        if "slurmctld" in running:
            try:
                jobs = self.slurm("squeue", "-h", "-o", "%i", timeout=10).stdout.split()
                if jobs:
                    self.slurm("scancel", *jobs, timeout=10)
                    end = time.monotonic() + grace
                    while time.monotonic() < end and self.slurm("squeue", "-h", "-o", "%i", timeout=10).stdout.split():
                        time.sleep(0.2)
            except subprocess.TimeoutExpired:
                pass  # the daemons go anyway
        left = terminate([p for p in [running.get("slurmd")] if p], grace)
        left += terminate(self.strays(), min(grace, 3))  # slurmstepd waits long on SIGTERM
        left += terminate([p for p in (running.get("slurmctld"), running.get("munged")) if p], grace)
        stopped = self.pids
        self.pids = {}
        if os.path.exists(self.pid_file):
            os.remove(self.pid_file)
        if left:
            raise ClusterError(f"still running after SIGKILL: {', '.join(f'{process_name(p)} {p}' for p in left)}")
        return stopped


# --- command line ---------------------------------------------------------------------------

def ports_pair(text):
    m = re.fullmatch(r"(\d+),(\d+)", text)
    if not m or not all(1024 <= int(p) <= 65535 for p in m.groups()):
        raise argparse.ArgumentTypeError(f"'{text}' is not two ports CTLD,SLURMD between 1024 and 65535")
    return int(m.group(1)), int(m.group(2))


def positive_seconds(text):
    if not re.fullmatch(r"\d+", text) or int(text) < 1:
        raise argparse.ArgumentTypeError(f"'{text}' is not a positive number of seconds")
    return int(text)


class UsageError(ClusterError):
    """A bad option: exit status 2 (a cluster that does not start or stop: 1)."""


class OneLineParser(argparse.ArgumentParser):
    def error(self, message):
        raise UsageError(message)


def main(argv=None):
    p = OneLineParser(prog=PROG, description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", parser_class=OneLineParser, metavar="{install,start,env,status,stop}")
    sub.required = True
    sub.add_parser("install", help="apt-get the missing Debian packages")
    for name, hlp in (("start", "start the cluster and wait until its node is idle"),
                      ("env", "print the export line for SLURM_CONF"),
                      ("status", "show which daemons run, and sinfo"),
                      ("stop", "cancel the jobs and stop the daemons by their pids")):
        s = sub.add_parser(name, help=hlp)
        s.add_argument("--dir", default=os.environ.get("EFSI_SLURM_DIR", DEFAULT_DIR),
                       help=f"scratch directory of the cluster (default $EFSI_SLURM_DIR or {DEFAULT_DIR})")
        if name == "start":
            s.add_argument("--ports", type=ports_pair, help="slurmctld,slurmd ports (default: two free ones)")
            s.add_argument("--task-plugin", choices=("affinity", "none"), default="affinity",
                           help="affinity (default) pins tasks to their cores; none leaves them free")
            s.add_argument("--timeout", type=positive_seconds, default=60, help="seconds to wait for idle (60)")
    try:
        args = p.parse_args(argv)
        if args.command == "install":
            install()
            return 0
        c = LocalCluster(args.dir, ports=getattr(args, "ports", None), task_plugin=getattr(args, "task_plugin", "affinity"))
        if args.command == "start":
            t0 = time.monotonic()
            c.start(timeout=args.timeout)
            print(f"node {c.node} idle after {time.monotonic() - t0:.1f} s; daemons {c.pids}")
            print(f"export SLURM_CONF={c.conf}")
        elif args.command == "env":
            print(f"export SLURM_CONF={c.conf}")
        elif args.command == "status":
            running = c.running()
            for name in DAEMONS:
                pid = c.pids.get(name)
                print(f"{name:10s} {'running, pid ' + str(pid) if name in running else 'not running'}")
            if "slurmctld" in running:
                print(c.slurm("sinfo").stdout, end="")
            return 0 if len(running) == len(DAEMONS) else 1
        elif args.command == "stop":
            stopped = c.stop()
            print(f"stopped {stopped}" if stopped else f"nothing of {c.dir} was running")
        return 0
    except ClusterError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 2 if isinstance(e, UsageError) else 1
    except (OSError, subprocess.SubprocessError) as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
