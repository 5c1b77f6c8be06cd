"""The scaling sweeps of EFSI-Bench in one place (docs/numerics.md, "Experiments", the paper's Tables 1-4).

campaign.py runs them here through mpirun, writes them as SLURM batch scripts, and prints
them for the JUBE definition in harness/jube/; everything that names a rank count, a
configuration or a driver option comes from this module.  Standard library only.

A configuration is written `METHOD-COMM[-VARIANT]`: `acm-sync`, `sor-async-1e-3`, `fft-sync`.
The methods, the halo modes each takes and the variants a campaign sweeps (SOR's calibrated
tolerances) come from the drivers' method registry (`weak_scaling --list-methods`), so a
method added to the solver joins every sweep that runs all methods without an edit here.
"""

import dataclasses
import functools
import os
import re
import subprocess

COMMS = ("sync", "async")
REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# The paper's five configurations (Tables 2 and 4): ACM with synchronous halos, SOR with
# either halo mode at both tolerances.  They are the paper's experiment, so they are named.
PAPER_CONFIGS = ("acm-sync", "sor-sync-1e-3", "sor-async-1e-3", "sor-sync-1e-4", "sor-async-1e-4")
# The comparison the paper left open: SMAC with multigrid at its calibrated V-cycle counts,
# the same tolerances as SOR's.  The cluster sweeps run it beside the paper's five.
OPEN_QUESTION_CONFIGS = ("mg-sync-1e-3", "mg-sync-1e-4")
# SOR with temporal blocking (4 sweeps between exchanges, --sweeps-per-exchange): not the
# paper's pattern, the same N_S; an extra series beside the paper's.
BLOCKED_CONFIGS = ("sor-sync-1e-3-k4", "sor-async-1e-3-k4", "sor-sync-1e-4-k4", "sor-async-1e-4-k4")
ALL = "all"  # a sweep's configurations: every registered method, halo mode and variant


class SweepError(ValueError):
    """A sweep, configuration or rank list that cannot be run; the message is one line."""


@dataclasses.dataclass(frozen=True)
class Method:
    name: str
    comms: tuple             # the halo modes it takes
    variants: tuple          # of (label, driver args); empty: one run per halo mode


@dataclasses.dataclass(frozen=True)
class Config:
    method: str
    comm: str
    variant: str = ""        # "" for a method without variants
    variant_args: tuple = ()

    @property
    def name(self):
        return "-".join(p for p in (self.method, self.comm, self.variant) if p)

    def driver_args(self):
        return ["--method", self.method, "--comm", self.comm, *self.variant_args]


def parse_catalog(text):
    """The methods from `--list-methods` output (method_registry.hpp, describe_methods)."""
    methods, variants = {}, {}
    for line in text.splitlines():
        kind, _, rest = line.partition(" ")
        fields = rest.split("|")
        if kind == "method" and len(fields) == 6:
            methods[fields[0]] = ("sync", "async") if fields[5] == "async" else ("sync",)
        elif kind == "variant" and len(fields) == 3:
            variants.setdefault(fields[0], []).append((fields[1], tuple(fields[2].split())))
    if not methods:
        raise SweepError("the method list from --list-methods is empty or unreadable")
    return {n: Method(n, comms, tuple(variants.get(n, ()))) for n, comms in methods.items()}


def catalog_driver(bin_dir=None):
    """The driver that lists the methods: bin_dir's, else $EFSI_BIN_DIR's, else this checkout's
    build (SLURM scripts may name a bin directory on a cluster that is not this machine)."""
    candidates = [d for d in (bin_dir, os.environ.get("EFSI_BIN_DIR"), os.path.join(REPO, "build", "bin")) if d]
    for d in candidates:
        exe = os.path.join(os.path.abspath(d), "weak_scaling")
        if os.access(exe, os.X_OK):
            return exe
    raise SweepError(f"no weak_scaling in {' or '.join(candidates)} to list the pressure methods "
                     "(build the drivers, or give --bin-dir)")


@functools.lru_cache(maxsize=None)
def _catalog_of(exe):
    r = subprocess.run([exe, "--list-methods"], capture_output=True, text=True, timeout=60)
    if r.returncode != 0:
        raise SweepError(f"{exe} --list-methods failed with status {r.returncode}")
    return parse_catalog(r.stdout)


def catalog(bin_dir=None):
    return _catalog_of(catalog_driver(bin_dir))


def all_configs(methods):
    """Every method in every halo mode it takes, at each of its variants."""
    out = []
    for m in methods.values():
        for comm in m.comms:
            out += [Config(m.name, comm, label, args) for label, args in m.variants] or [Config(m.name, comm)]
    return out


def parse_config(text, methods):
    """`sor-async-1e-3` -> Config('sor', 'async', '1e-3', ('--eps', '1e-3')); SweepError names what is wrong."""
    parts = text.strip().split("-", 2)
    if len(parts) < 2 or parts[0] not in methods or parts[1] not in COMMS:
        raise SweepError(f"configuration '{text}' is not METHOD-COMM[-VARIANT] with METHOD in "
                         f"{'|'.join(methods)} and COMM in {'|'.join(COMMS)}")
    m, comm = methods[parts[0]], parts[1]
    variant = parts[2] if len(parts) == 3 else ""
    if comm not in m.comms:
        raise SweepError(f"configuration '{text}': {m.name} has no {comm} halo mode")
    labels = [label for label, _ in m.variants]
    takers = [n for n, other in methods.items() if other.variants]
    if variant and not labels:
        raise SweepError(f"configuration '{text}': {m.name} takes no variant (only {', '.join(takers)} do)")
    if labels and variant not in labels:
        raise SweepError(f"configuration '{text}': {m.name} needs a variant, one of {', '.join(labels)} "
                         f"(e.g. {m.name}-{comm}-{labels[0]})")
    args = dict(m.variants).get(variant, ())
    return Config(m.name, comm, variant, args)


def parse_configs(text, methods):
    configs = [parse_config(t, methods) for t in text.split(",") if t.strip()]
    if not configs:
        raise SweepError("no configuration given")
    return configs


def parse_ranks(text):
    """`1,2,4` or `1:8192` (powers of two from 1 to 8192) -> sorted distinct positive ints."""
    ranks = []
    for item in text.split(","):
        item = item.strip()
        m = re.fullmatch(r"(\d+):(\d+)", item)
        if m:
            lo, hi = int(m.group(1)), int(m.group(2))
            if lo < 1 or hi < lo or lo & (lo - 1) or hi & (hi - 1):
                raise SweepError(f"rank range '{item}' must be POW2:POW2 with 1 <= lo <= hi")
            r = lo
            while r <= hi:
                ranks.append(r)
                r *= 2
        elif re.fullmatch(r"\d+", item) and int(item) >= 1:
            ranks.append(int(item))
        else:
            raise SweepError(f"rank count '{item}' is not a positive integer or a range LO:HI")
    return sorted(set(ranks))


def powers_of_two(lo, hi):
    return parse_ranks(f"{lo}:{hi}")


@dataclasses.dataclass(frozen=True)
class Sweep:
    name: str
    driver: str              # executable in the bin dir
    experiment: str          # the CSV's experiment column
    ranks: tuple
    config_names: tuple      # configuration names, or (ALL,)
    driver_options: tuple    # options every run gets, besides the configuration
    description: str

    def configs(self, methods):
        if self.config_names == (ALL,):
            return all_configs(methods)
        return [parse_config(c, methods) for c in self.config_names]


def _sweep(name, driver, experiment, ranks, configs, options, description):
    return Sweep(name, driver, experiment, tuple(ranks), tuple(configs), tuple(options), description)


# The paper's sweeps at the paper's sizes (for clusters) and their copies for this machine.
# Driver defaults are the paper's values (64^3 cells and 2 particles per rank, ACM 50 steps
# at dt 1.25e-5, SOR 10 steps at 6.25e-5, calibrated N_S, N_C = 20), so the cluster sweeps
# pass no size options.
SWEEPS = {
    "weak": _sweep("weak", "weak_scaling", "weak", powers_of_two(1, 8192),
                   PAPER_CONFIGS + OPEN_QUESTION_CONFIGS + BLOCKED_CONFIGS,
                   (), "paper section 3.2: 64^3 cells and 2 particles per rank, 1 to 8192 ranks"),
    "strong": _sweep("strong", "strong_scaling", "strong", powers_of_two(1024, 8192),
                     PAPER_CONFIGS + OPEN_QUESTION_CONFIGS + BLOCKED_CONFIGS, ("--scale", "1"),
                     "paper section 3.3: 2048 x 1024 x 1024 cells, 16384 particles, 1024 to 8192 ranks"),
    # This machine: the same block per rank on 1 and 2 ranks, every registered method and mode.
    "local-weak": _sweep("local-weak", "weak_scaling", "weak", (1, 2), (ALL,), (),
                         "paper weak block (64^3 per rank) on 1 and 2 ranks, every method and mode"),
    # The strong case divided by 16 per direction (128 x 64 x 64 cells, 4 particles).
    "local-strong": _sweep("local-strong", "strong_scaling", "strong", (1, 2), (ALL,),
                           ("--scale", "16"),
                           "paper strong case / 16 per direction (128 x 64 x 64) on 1 and 2 ranks"),
    # The README's main job: both local sweeps with 3 measured steps each (a few minutes).
    "quick-weak": _sweep("quick-weak", "weak_scaling", "weak", (1, 2), (ALL,), ("--steps", "3"),
                         "as local-weak, 3 measured steps (the README's quick campaign)"),
    "quick-strong": _sweep("quick-strong", "strong_scaling", "strong", (1, 2), (ALL,),
                           ("--scale", "16", "--steps", "3"),
                           "as local-strong, 3 measured steps (the README's quick campaign)"),
    # A few seconds in all: the JUBE test and a smoke run of the whole chain.  The block stays
    # the paper's (a smaller one no longer holds the 3.6-long particle lattice cell).
    "mini": _sweep("mini", "weak_scaling", "weak", (1, 2), ("acm-sync", "sor-async-1e-3", "mg-sync-1e-3"),
                   ("--steps", "2"),
                   "paper weak block (64^3 per rank), 2 measured steps, 1 and 2 ranks (tests)"),
}


def get_sweep(name):
    try:
        return SWEEPS[name]
    except KeyError:
        raise SweepError(f"unknown sweep '{name}' (one of {', '.join(SWEEPS)})") from None


def driver_command(sweep, config, extra_options=(), csv_path=None):
    """The driver's argument list (without the launcher) for one run of the sweep.

    extra_options are `--flag value` pairs; one that the sweep sets too replaces the sweep's.
    """
    options = dict(zip(sweep.driver_options[::2], sweep.driver_options[1::2]))
    options.update(zip(extra_options[::2], extra_options[1::2]))
    args = [sweep.driver, *config.driver_args()]
    for flag, value in options.items():
        args += [flag, str(value)]
    if csv_path:
        args += ["--csv", csv_path]
    return args
