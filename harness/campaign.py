#!/usr/bin/env python3
"""EFSI-Bench scaling campaigns: run a sweep here, or write it for a cluster (harness/CAMPAIGN.md).

  campaign.py local  [--sweep local-weak] [--ranks 1,2] [--configs ...] [--repeats N] --csv FILE
  campaign.py slurm  --out DIR [--sweep weak --sweep strong] [--cores-per-node N] [--cpus-per-task C] ...
  campaign.py simulate --platform ricc|ricc-modern|FILE.xml --csv FILE [--sweep weak] [--ranks ...]
                                                          (the simulation build under SimGrid)
  campaign.py list   --sweep NAME --what ranks|configs   (comma-separated, for JUBE)
  campaign.py collect --into FILE CSV...                 (append rows under a lock)

The sweeps (rank counts, configurations, driver options) live in campaign_sweeps.py and
serve all four.  Standard library only.  A bad option gives one line on stderr and exit
status 2.
"""

import argparse
import csv
import fcntl
import io
import math
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import campaign_sweeps as sweeps  # noqa: E402
import paper_tables  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_BIN_DIR = os.path.join(REPO, "build", "bin")
PROG = "campaign.py"


class UsageError(Exception):
    """A bad option or argument: one line, exit status 2."""


class OneLineParser(argparse.ArgumentParser):
    def error(self, message):
        raise UsageError(message)


def positive_int(text):
    if not re.fullmatch(r"\d+", text.strip()) or int(text) < 1:
        raise argparse.ArgumentTypeError(f"'{text}' is not a positive integer")
    return int(text)


def nonnegative_int(text):
    if not re.fullmatch(r"\d+", text.strip()):
        raise argparse.ArgumentTypeError(f"'{text}' is not a non-negative integer")
    return int(text)


def ranks_list(text):
    try:
        return sweeps.parse_ranks(text)
    except sweeps.SweepError as e:
        raise argparse.ArgumentTypeError(str(e)) from None


def config_list(text):
    """Configuration names; they are checked against the drivers' method list later."""
    names = tuple(t.strip() for t in text.split(",") if t.strip())
    if not names:
        raise argparse.ArgumentTypeError(f"no configuration in '{text}'")
    return names


def sweep_name(text):
    if text not in sweeps.SWEEPS:
        raise argparse.ArgumentTypeError(f"unknown sweep '{text}' (one of {', '.join(sweeps.SWEEPS)})")
    return text


def slurm_time(text):
    # Slurm's forms: MM, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS
    if not re.fullmatch(r"(\d+-)?\d+(:\d\d){0,2}", text) or not re.search(r"[1-9]", text):
        raise argparse.ArgumentTypeError(f"time '{text}' is not a Slurm time limit like 00:30:00 or 1-00:00:00")
    return text


def slurm_name(text):
    if not re.fullmatch(r"[A-Za-z0-9_.+-]+", text):
        raise argparse.ArgumentTypeError(f"'{text}' is not a plain Slurm name (letters, digits, _ . + -)")
    return text


# --- size options passed to the drivers -------------------------------------------------------

SIZE_OPTIONS = (  # (option, driver flag, type, help)
    ("--local", "--local", positive_int, "cells per rank per direction (weak_scaling)"),
    ("--particles-per-rank", "--particles-per-rank", nonnegative_int, "particles per rank (weak_scaling)"),
    ("--scale", "--scale", positive_int, "divide the strong case by S per direction (strong_scaling)"),
    ("--steps", "--steps", positive_int, "measured steps (default: the paper's)"),
)


def add_sweep_options(p, default_sweeps):
    p.add_argument("--sweep", type=sweep_name, action="append", dest="sweeps",
                   help=f"which sweep (repeatable; default {' and '.join(default_sweeps)}): {', '.join(sweeps.SWEEPS)}")
    p.add_argument("--ranks", type=ranks_list, help="rank counts instead of the sweep's: 1,2,4 or 1:8192 (powers of two)")
    p.add_argument("--configs", type=config_list,
                   help="configurations instead of the sweep's, e.g. acm-sync,sor-async-1e-3")
    p.add_argument("--repeats", type=positive_int, default=1, help="runs of every point (default 1)")
    p.add_argument("--bin-dir", default=None, help=f"directory of the drivers (default {DEFAULT_BIN_DIR})")
    for opt, _, typ, hlp in SIZE_OPTIONS:
        p.add_argument(opt, type=typ, help=hlp)
    p.set_defaults(default_sweeps=default_sweeps)


def selected_sweeps(args):
    return [sweeps.get_sweep(n) for n in (args.sweeps or args.default_sweeps)]


def size_options(args, sweep):
    """The size options the user gave that apply to this sweep's driver."""
    out = []
    applies = {"weak_scaling": ("--local", "--particles-per-rank", "--steps"),
               "strong_scaling": ("--scale", "--steps")}[sweep.driver]
    for opt, flag, _, _ in SIZE_OPTIONS:
        value = getattr(args, opt[2:].replace("-", "_"))
        if value is not None:
            if flag not in applies:
                raise UsageError(f"{opt} does not apply to the {sweep.name} sweep ({sweep.driver})")
            out += [flag, str(value)]
    return out


def sweep_configs(args, sweep):
    """The sweep's configurations, or --configs, resolved against the drivers' method list."""
    methods = sweeps.catalog(args.bin_dir)
    if args.configs:
        return [sweeps.parse_config(c, methods) for c in args.configs]
    return sweep.configs(methods)


def points(args, sweep):
    """(repeat, ranks, config) in run order: whole sweeps repeated, so noise spreads evenly."""
    ranks = args.ranks or sweep.ranks
    configs = sweep_configs(args, sweep)
    return [(rep, r, c) for rep in range(args.repeats) for r in ranks for c in configs]


def bin_dir(args, check=True):
    d = os.path.abspath(args.bin_dir or DEFAULT_BIN_DIR)
    if check:
        for sweep in selected_sweeps(args):
            exe = os.path.join(d, sweep.driver)
            if not os.access(exe, os.X_OK):
                raise UsageError(f"no executable {exe} (build it, or give --bin-dir)")
    return d


# --- local: run here through mpirun (or srun inside an allocation) ----------------------------

def run_point(cmd, env, timeout, cwd=None):
    """(status or "timeout", output, wall seconds) of one run."""
    t0 = time.monotonic()
    try:
        r = subprocess.run(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=timeout,
                           cwd=cwd)
        rc, out = r.returncode, r.stdout
    except subprocess.TimeoutExpired as e:
        rc, out = "timeout", (e.stdout or b"").decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
    return rc, out, time.monotonic() - t0


def failure_lines(out):
    """What a failed run said: its error lines, else its last lines."""
    lines = [l for l in out.splitlines() if l.strip()]
    return " | ".join([l for l in lines if "error" in l.lower()][:2] or lines[-3:])



def srun_prefix(ranks, threads, mpi, per_node=None):
    """srun for one run inside an allocation.  --mpi names the PMI the MPI library starts
    through: plain srun leaves it to the site's MpiDefault, and with Debian's SLURM (MpiDefault
    none) and Open MPI (no SLURM PMI-1/PMI-2) every rank then starts as its own 1-rank job."""
    cmd = ["srun", f"--mpi={mpi}", f"--ntasks={ranks}"]
    if per_node:
        cmd.append(f"--ntasks-per-node={per_node}")
    return cmd + [f"--cpus-per-task={threads}", "--cpu-bind=cores"]


def mpirun_in_allocation(ranks, threads, per_node):
    """mpirun inside an allocation: Open MPI reads the nodes from SLURM and starts its daemons
    with srun; --map-by places the ranks as sbatch asked and gives each its threads' cores."""
    pe = f":PE={threads}" if threads > 1 else ""
    return ["mpirun", "-n", str(ranks), "--map-by", f"ppr:{per_node}:node{pe}", "--bind-to", "core"]


def launcher_command(launcher, ranks, threads, cores, bind, srun_mpi="pmix"):
    """The launch prefix and whether the run is oversubscribed (more threads than cores)."""
    over = ranks * threads > cores
    if launcher == "srun":
        return srun_prefix(ranks, threads, srun_mpi), over
    cmd = [launcher, "-n", str(ranks)]
    if over:
        cmd += ["--oversubscribe", "--bind-to", "none"]
    elif bind:
        # One rank per `threads` cores; the rank's threads stay on them.
        cmd += ["--map-by", f"slot:PE={threads}", "--bind-to", "core"] if threads > 1 else ["--bind-to", "core"]
    return cmd, over


def cmd_local(args):
    d = bin_dir(args, check=not args.dry_run)
    if not args.csv:
        raise UsageError("--csv FILE is required (where the result rows go)")
    csv_path = os.path.abspath(args.csv)
    if not args.dry_run and not shutil.which(args.launcher):
        raise UsageError(f"launcher '{args.launcher}' not found")
    env = dict(os.environ, OMP_NUM_THREADS=str(args.threads))
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT", "1")
    env.setdefault("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
    # Threads pinned inside each rank's cores when the launcher binds the ranks; unbound ranks
    # (oversubscribed, --no-bind) would all pin their threads from core 0 on, so they float.
    bound_env = dict(env)
    bound_env.setdefault("OMP_PLACES", "cores")
    bound_env.setdefault("OMP_PROC_BIND", "close")
    unbound_env = dict(env)
    unbound_env.setdefault("OMP_PROC_BIND", "false")
    runs = [(s, p) for s in selected_sweeps(args) for p in points(args, s)]
    extra = {s.name: size_options(args, s) for s in selected_sweeps(args)}
    failed = 0
    for n, (sweep, (rep, ranks, config)) in enumerate(runs, 1):
        prefix, over = launcher_command(args.launcher, ranks, args.threads, args.cores, not args.no_bind,
                                        args.srun_mpi)
        drv = sweeps.driver_command(sweep, config, extra[sweep.name], csv_path)
        cmd = prefix + [os.path.join(d, drv[0])] + drv[1:]
        run_env = unbound_env if over or args.no_bind else bound_env
        tag = f"[{n}/{len(runs)}] {sweep.name} ranks={ranks} threads={args.threads} {config.name} repeat={rep + 1}"
        note = " (oversubscribed: marked, not valid)" if over else ""
        omp = " ".join(f"{k}={run_env[k]}" for k in ("OMP_NUM_THREADS", "OMP_PLACES", "OMP_PROC_BIND") if k in run_env)
        print(f"{tag}{note}\n  {omp} {shlex.join(cmd)}", flush=True)
        if args.dry_run:
            continue
        rc, out, wall = run_point(cmd, run_env, args.timeout)
        if rc != 0:
            failed += 1
            print(f"  FAILED ({rc}) after {wall:.1f} s: {failure_lines(out)}", flush=True)
        else:
            print(f"  done in {wall:.1f} s", flush=True)
    if not args.dry_run:
        print(f"{len(runs) - failed} of {len(runs)} runs finished; rows in {csv_path}")
    return 1 if failed else 0


# --- slurm: batch scripts for clusters ---------------------------------------------------------

DEFAULT_TIME = {"weak_scaling": "00:30:00", "strong_scaling": "02:00:00"}


def slurm_script(sweep, ranks, configs, args, d, extra, cmdline):
    rpn = args.ranks_per_node or max(1, args.cores_per_node // args.cpus_per_task)
    nodes = math.ceil(ranks / rpn)
    per_node = min(ranks, rpn)
    name = f"{args.job_prefix}-{sweep.name}-{ranks:05d}"
    lines = [
        "#!/bin/bash",
        f"#SBATCH --job-name={name}",
        f"#SBATCH --nodes={nodes}",
        f"#SBATCH --ntasks={ranks}",
        f"#SBATCH --ntasks-per-node={per_node}",
        f"#SBATCH --cpus-per-task={args.cpus_per_task}",
        f"#SBATCH --time={args.time or DEFAULT_TIME[sweep.driver]}",
        f"#SBATCH --output={name}-%j.out",
    ]
    if args.exclusive:
        lines.append("#SBATCH --exclusive")
    if args.account:
        lines.append(f"#SBATCH --account={args.account}")
    if args.partition:
        lines.append(f"#SBATCH --partition={args.partition}")
    if args.qos:
        lines.append(f"#SBATCH --qos={args.qos}")
    rows = shlex.quote(os.path.abspath(args.rows_dir)) if args.rows_dir else '"${SLURM_SUBMIT_DIR:-$PWD}/rows"'
    lines += [
        f"# EFSI-Bench {sweep.name} sweep ({sweep.description}): {ranks} ranks x "
        f"{args.cpus_per_task} threads on {nodes} node(s), {len(configs)} configuration(s) x {args.repeats} repeat(s).",
        f"# Written by: {cmdline}",
        "set -uo pipefail",
        f"export OMP_NUM_THREADS={args.cpus_per_task}",
        "export OMP_PLACES=cores",
        "export OMP_PROC_BIND=close",
        "# Slurm 22.05 and later no longer pass --cpus-per-task from sbatch to srun.",
        f"export SRUN_CPUS_PER_TASK={args.cpus_per_task}",
        f"BIN={shlex.quote(d)}",
        "# One CSV per job, so that no two jobs ever append to the same file on a shared file",
        "# system; `campaign.py collect` gathers them.",
        f"ROWS={rows}",
        f'CSV="$ROWS/{name}-${{SLURM_JOB_ID:-nojob}}.csv"',
        'mkdir -p "$ROWS"',
        "status=0",
        'run() { echo "+ $*"; "$@" || { echo "failed with status $?: $*" >&2; status=1; }; }',
    ]
    if sweep.driver == "strong_scaling":
        scale = dict(zip(extra[::2], extra[1::2])).get("--scale",
                                                       dict(zip(sweep.driver_options[::2], sweep.driver_options[1::2])).get("--scale", "1"))
        lines.append(f'# Decomposition, local block and memory per rank, before anything is allocated:')
        lines.append(f'run "$BIN/strong_scaling" --dry-run --ranks {ranks} --scale {scale}')
    if args.launcher == "srun":
        launch = shlex.join(srun_prefix(ranks, args.cpus_per_task, args.srun_mpi, per_node))
    else:
        launch = shlex.join(mpirun_in_allocation(ranks, args.cpus_per_task, per_node))
    for rep in range(args.repeats):
        for config in configs:
            drv = sweeps.driver_command(sweep, config, extra)
            body = " ".join(shlex.quote(a) for a in drv[1:])
            lines.append(f'run {launch} "$BIN/{drv[0]}" {body} --csv "$CSV"'
                         f"  # {config.name}, repeat {rep + 1}")
    lines.append("exit $status")
    return name, nodes, "\n".join(lines) + "\n"


SUBMIT_ALL = """\
#!/bin/bash
# Submits every job of this campaign (options are passed to each sbatch) and appends
# "JOBID SCRIPT" to submitted.txt; each job writes its rows to rows/NAME-JOBID.csv.
set -euo pipefail
cd "$(dirname "$0")"
for script in {scripts}; do
  id=$(sbatch --parsable "$@" "$script")
  id=${{id%%;*}}
  echo "$id $script" >> submitted.txt
  echo "submitted $script as job $id"
done
"""


def cmd_slurm(args):
    if args.cpus_per_task > args.cores_per_node:
        raise UsageError(f"--cpus-per-task {args.cpus_per_task} exceeds --cores-per-node {args.cores_per_node}")
    if args.ranks_per_node and args.ranks_per_node * args.cpus_per_task > args.cores_per_node:
        raise UsageError(f"--ranks-per-node {args.ranks_per_node} x --cpus-per-task {args.cpus_per_task} "
                         f"exceeds --cores-per-node {args.cores_per_node}")
    d = bin_dir(args, check=False)
    out = os.path.abspath(args.out)
    extras = {s.name: size_options(args, s) for s in selected_sweeps(args)}  # checked before writing
    configs_of = {s.name: sweep_configs(args, s) for s in selected_sweeps(args)}
    os.makedirs(out, exist_ok=True)
    cmdline = shlex.join([PROG] + sys.argv[1:])
    manifest = [("script", "sweep", "driver", "ranks", "nodes", "cpus_per_task", "configs", "repeats", "rows")]
    names = []
    for sweep in selected_sweeps(args):
        extra = extras[sweep.name]
        configs = configs_of[sweep.name]
        for ranks in args.ranks or sweep.ranks:
            name, nodes, text = slurm_script(sweep, ranks, configs, args, d, extra, cmdline)
            path = os.path.join(out, name + ".sbatch")
            with open(path, "w") as f:
                f.write(text)
            os.chmod(path, 0o755)
            names.append(name + ".sbatch")
            rows = os.path.join(os.path.abspath(args.rows_dir) if args.rows_dir else "rows", f"{name}-JOBID.csv")
            manifest.append((name + ".sbatch", sweep.name, sweep.driver, ranks, nodes, args.cpus_per_task,
                             " ".join(c.name for c in configs), args.repeats, rows))
    with open(os.path.join(out, "submit_all.sh"), "w") as f:
        f.write(SUBMIT_ALL.format(scripts=" ".join(names)))
    os.chmod(os.path.join(out, "submit_all.sh"), 0o755)
    with open(os.path.join(out, "manifest.csv"), "w", newline="") as f:
        csv.writer(f).writerows(manifest)
    print(f"wrote {len(names)} batch scripts, submit_all.sh and manifest.csv to {out}")
    return 0


# --- list and collect: for JUBE ---------------------------------------------------------------

def cmd_list(args):
    sweep = sweeps.get_sweep(args.sweep)
    if args.what == "configs":
        values = [c.name for c in sweep.configs(sweeps.catalog(args.bin_dir))]
    else:
        values = {"ranks": [str(r) for r in sweep.ranks], "driver": [sweep.driver]}[args.what]
    sys.stdout.write(",".join(values))
    return 0


def cmd_collect(args):
    """Appends the rows of the CSV files to --into under an exclusive lock, header once."""
    into = os.path.abspath(args.into)
    rows, header = [], None
    for path in args.files:
        with open(path, newline="") as f:
            data = list(csv.reader(f))
        if not data:
            continue
        if header is None:
            header = data[0]
        elif data[0] != header:
            raise UsageError(f"{path}: its header differs from {args.files[0]}'s")
        rows += data[1:]
    if header is None:
        raise UsageError("no rows to collect")
    os.makedirs(os.path.dirname(into) or ".", exist_ok=True)
    with open(into, "a+", newline="") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        f.seek(0)
        first = f.readline()
        if not first:
            csv.writer(f).writerow(header)
        elif next(csv.reader(io.StringIO(first))) != header:
            raise UsageError(f"{into}: its header differs from the rows collected")
        f.seek(0, os.SEEK_END)
        csv.writer(f).writerows(rows)
    print(f"collected {len(rows)} row(s) into {into}")
    return 0


# --- simulate: the simulation build under SimGrid's SMPI (harness/simgrid/README.md) ----------

DEFAULT_SIM_BIN_DIR = os.path.join(REPO, "build-simgrid", "bin")
PLATFORMS = os.path.join(REPO, "harness", "simgrid", "platforms")
PAPER_TABLES = paper_tables.PAPER_TABLES


def platform_file(text):
    path = text if text.endswith(".xml") else os.path.join(PLATFORMS, text + ".xml")
    if not os.path.isfile(path):
        names = sorted(n[:-4] for n in os.listdir(PLATFORMS) if n.endswith(".xml"))
        raise argparse.ArgumentTypeError(f"platform '{text}' is neither a file nor one of {', '.join(names)}")
    return os.path.abspath(path)


def platform_name(path):
    """The name a simulated row carries (the hosts' property `platform`), else the file's."""
    with open(path) as f:
        m = re.search(r'<prop\s+id="platform"\s+value="([^"]+)"', f.read())
    return m.group(1) if m else os.path.splitext(os.path.basename(path))[0]


def paper_sor_sweeps():
    """The paper's SOR sweeps per step at each weak-scaling tolerance (Table 1): {eps: (N_S, N_C)}."""
    return {eps: (int(ns), int(nc)) for (experiment, eps), (ns, nc, _) in paper_tables.sor_sweeps().items()
            if experiment == "weak"}


def simulated_args(config):
    """A configuration's driver options for a prediction of the paper: SOR at the paper's own
    sweep counts for its tolerance (the calibration point ran them), not this suite's."""
    args = config.driver_args()
    if config.method == "sor" and config.variant:
        tolerance = config.variant.split("-k")[0]  # "1e-3-k4": 1e-3 with temporal blocking
        ns_nc = paper_sor_sweeps().get(paper_tables.eps_label(tolerance))
        if ns_nc is None:
            raise UsageError(f"no SOR sweep count in {PAPER_TABLES} for tolerance {config.variant}")
        args += ["--ns", str(ns_nc[0]), "--nc", str(ns_nc[1])]
    return args


def done_points(csv_path):
    """(experiment, method, comm, ns_per_step, ranks, simulated, halo, sweeps between exchanges)
    of the rows already in the CSV: a campaign stopped part-way goes on where it stopped."""
    if not os.path.exists(csv_path):
        return set()
    with open(csv_path, newline="") as f:
        return {(r["experiment"], r["method"], r["comm"], r["ns_per_step"], r["ranks"], r["simulated"],
                 r.get("halo", ""), paper_tables.blocking_label(r.get("sweeps_per_exchange")))
                for r in csv.DictReader(f) if r.get("valid") == "1"}


def cmd_simulate(args):
    if not args.csv:
        raise UsageError("--csv FILE is required (where the predicted rows go)")
    csv_path = os.path.abspath(args.csv)
    sim_dir = os.path.abspath(args.sim_bin_dir)
    run_sh = os.path.join(REPO, "harness", "simgrid", "run.sh")
    if not args.dry_run:
        for sweep in selected_sweeps(args):
            exe = os.path.join(sim_dir, sweep.driver)
            if not os.access(exe, os.X_OK):
                raise UsageError(f"no simulation build at {exe} (cmake --preset simgrid && cmake --build --preset "
                                 "simgrid, or give --sim-bin-dir)")
    name = platform_name(args.platform)
    done = done_points(csv_path)
    runs = []
    for sweep in selected_sweeps(args):
        extra = size_options(args, sweep)
        if "--steps" not in extra:
            extra += ["--steps", str(args.default_steps)]
        methods = sweeps.catalog(args.bin_dir)
        configs = ([sweeps.parse_config(c, methods) for c in args.configs] if args.configs
                   else [sweeps.parse_config(c, methods) for c in sweeps.PAPER_CONFIGS])
        for ranks in args.ranks or sweep.ranks:
            for config in configs:
                drv_args = simulated_args(config) + ["--halo", args.halo]
                ns = drv_args[drv_args.index("--ns") + 1] if "--ns" in drv_args else ""
                spe = drv_args[drv_args.index("--sweeps-per-exchange") + 1] if "--sweeps-per-exchange" in drv_args else ""
                key = (sweep.experiment, config.method, config.comm, ns, str(ranks), name, args.halo,
                       paper_tables.blocking_label(spe))
                runs.append((sweep, ranks, config, drv_args, extra, key in done))
    failed = 0
    for n, (sweep, ranks, config, drv_args, extra, skip) in enumerate(runs, 1):
        options = dict(zip(sweep.driver_options[::2], sweep.driver_options[1::2]))
        options.update(zip(extra[::2], extra[1::2]))
        cmd = ["bash", run_sh, args.platform, str(ranks), str(args.ranks_per_node),
               os.path.join(sim_dir, sweep.driver), *drv_args]
        for flag, value in options.items():
            cmd += [flag, str(value)]
        cmd += ["--csv", csv_path]
        tag = f"[{n}/{len(runs)}] {sweep.name} on {name}: {ranks} simulated ranks, {args.ranks_per_node} a node, {config.name}"
        if skip:
            print(f"{tag}: in {csv_path} already, skipped", flush=True)
            continue
        print(f"{tag}\n  {shlex.join(cmd)}", flush=True)
        if args.dry_run:
            continue
        # smpirun leaves its host file in the working folder while it runs: not in the checkout.
        with tempfile.TemporaryDirectory(prefix="efsi-simulate-") as work:
            rc, out, wall = run_point(cmd, None, args.timeout, cwd=work)
        if rc != 0:
            failed += 1
            print(f"  FAILED ({rc}) after {wall:.1f} s of simulator time: {failure_lines(out)}", flush=True)
        else:
            timing = [l.strip() for l in out.splitlines() if l.startswith("timing over")]
            print(f"  simulated in {wall:.1f} s: {timing[0] if timing else ''}", flush=True)
    if not args.dry_run:
        print(f"{len(runs) - failed} of {len(runs)} points in {csv_path}")
    return 1 if failed else 0


# --- command line ---------------------------------------------------------------------------

def add_srun_mpi_option(p):
    p.add_argument("--srun-mpi", type=slurm_name, default="pmix",
                   help="srun --mpi=TYPE: the PMI the MPI library starts through (default pmix; "
                        "`srun --mpi=list` shows a site's)")


def build_parser():
    p = OneLineParser(prog=PROG, description=__doc__.split("\n\n")[0])
    sub = p.add_subparsers(dest="command", parser_class=OneLineParser, metavar="{local,slurm,simulate,list,collect}")
    sub.required = True

    lo = sub.add_parser("local", help="run a sweep on this machine through mpirun and append to a CSV")
    add_sweep_options(lo, ["local-weak"])
    lo.add_argument("--csv", help="append the result rows here (required)")
    lo.add_argument("--threads", type=positive_int, default=1, help="OpenMP threads per rank (default 1)")
    lo.add_argument("--cores", type=positive_int, default=os.cpu_count() or 1,
                    help="cores on this machine; more ranks x threads are run oversubscribed (default: all)")
    lo.add_argument("--launcher", default="mpirun",
                    help="mpirun (default), mpiexec, another mpirun by path, or srun inside an allocation")
    add_srun_mpi_option(lo)
    lo.add_argument("--no-bind", action="store_true", help="do not bind ranks to cores")
    lo.add_argument("--timeout", type=positive_int, default=3600, help="seconds one run may take (default 3600)")
    lo.add_argument("--dry-run", action="store_true", help="print the commands, run nothing")
    lo.set_defaults(func=cmd_local)

    sl = sub.add_parser("slurm", help="write SLURM batch scripts (one job per rank count)")
    add_sweep_options(sl, ["weak", "strong"])
    sl.add_argument("--out", required=True, help="directory for the scripts")
    sl.add_argument("--rows-dir", help="where each job writes its CSV, NAME-JOBID.csv (default: rows/ beside "
                                       "the job's output, in the directory sbatch was run from)")
    sl.add_argument("--launcher", choices=("srun", "mpirun"), default="srun",
                    help="srun (default) or Open MPI's mpirun inside the allocation")
    add_srun_mpi_option(sl)
    sl.add_argument("--cores-per-node", type=positive_int, default=8,
                    help="cores per node (default 8, as on the paper's RICC nodes)")
    sl.add_argument("--cpus-per-task", type=positive_int, default=1, help="OpenMP threads per rank (default 1)")
    sl.add_argument("--ranks-per-node", type=positive_int, help="default: cores-per-node / cpus-per-task")
    sl.add_argument("--time", type=slurm_time, help="time limit per job (default 00:30:00 weak, 02:00:00 strong)")
    sl.add_argument("--account", type=slurm_name)
    sl.add_argument("--partition", type=slurm_name)
    sl.add_argument("--qos", type=slurm_name)
    sl.add_argument("--job-prefix", type=slurm_name, default="efsi")
    sl.add_argument("--no-exclusive", dest="exclusive", action="store_false", help="share nodes")
    sl.set_defaults(func=cmd_slurm)

    si = sub.add_parser("simulate", help="predict a sweep with the simulation build on a platform model "
                                         "(SimGrid's SMPI), appending to a CSV; points already there are skipped")
    add_sweep_options(si, ["weak"])
    si.set_defaults(repeats=1)
    si.add_argument("--platform", type=platform_file, required=True,
                    help="a platform of harness/simgrid/platforms (ricc, ricc-modern, dev-2core) or an XML file")
    si.add_argument("--csv", help="append the predicted rows here (required)")
    si.add_argument("--ranks-per-node", type=positive_int, default=8,
                    help="simulated ranks per node (default 8, one per core of a RICC node)")
    si.add_argument("--halo", choices=("direct", "phased"), default="phased",
                    help="how the full exchanges reach the corners (default phased: 6 messages, which the "
                         "simulator moves about 2x faster than 26 at 512 ranks)")
    si.add_argument("--sim-bin-dir", default=DEFAULT_SIM_BIN_DIR,
                    help=f"the simulation build's drivers (default {DEFAULT_SIM_BIN_DIR})")
    si.add_argument("--timeout", type=positive_int, default=3600, help="seconds one point may take (default 3600)")
    si.add_argument("--dry-run", action="store_true", help="print the commands, run nothing")
    si.set_defaults(func=cmd_simulate, default_steps=2)

    li = sub.add_parser("list", help="print a sweep's rank counts or configurations, comma-separated")
    li.add_argument("--sweep", type=sweep_name, required=True)
    li.add_argument("--what", choices=("ranks", "configs", "driver"), required=True)
    li.add_argument("--bin-dir", default=None,
                    help=f"the drivers that list the methods, for --what configs (default {DEFAULT_BIN_DIR})")
    li.set_defaults(func=cmd_list)

    co = sub.add_parser("collect", help="append result CSVs to one CSV, header once, under a lock")
    co.add_argument("--into", required=True)
    co.add_argument("files", nargs="+")
    co.set_defaults(func=cmd_collect)
    return p


def main(argv=None):
    try:
        args = build_parser().parse_args(argv)
        return args.func(args)
    except (UsageError, sweeps.SweepError) as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 2
    except OSError as e:
        print(f"{PROG}: error: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
