"""The scaling sweeps of EFSI-Bench in one place (docs/numerics.md, "Experiments", the paper's Tables 1-4).

campaign.py runs them here through mpirun, writes them as SLURM batch scripts, and prints
them for the JUBE definition in harness/jube/; everything that names a rank count, a
configuration or a driver option comes from this module.  Standard library only.

A configuration is written `METHOD-COMM[-EPS]`: `acm-sync`, `sor-async-1e-3`, `fft-sync`.
The SOR tolerance picks the calibrated N_S in the driver (docs/numerics.md, "SMAC"); ACM and FFT have
none.
"""

import dataclasses
import re

METHODS = ("acm", "sor", "fft")
COMMS = ("sync", "async")
EPS_VALUES = ("1e-3", "1e-4")

# The paper's five configurations (Tables 2 and 4): ACM with synchronous halos, SOR with
# either halo mode at both tolerances.
PAPER_CONFIGS = ("acm-sync", "sor-sync-1e-3", "sor-async-1e-3", "sor-sync-1e-4", "sor-async-1e-4")
# Every method in every halo mode: the paper's five, ACM async and the FFT reference.
ALL_CONFIGS = PAPER_CONFIGS + ("acm-async", "fft-sync", "fft-async")


class SweepError(ValueError):
    """A sweep, configuration or rank list that cannot be run; the message is one line."""


@dataclasses.dataclass(frozen=True)
class Config:
    method: str
    comm: str
    eps: str = ""  # "" for acm and fft

    @property
    def name(self):
        return "-".join(p for p in (self.method, self.comm, self.eps) if p)

    def driver_args(self):
        args = ["--method", self.method, "--comm", self.comm]
        if self.eps:
            args += ["--eps", self.eps]
        return args


def parse_config(text):
    """`sor-async-1e-3` -> Config('sor', 'async', '1e-3'); SweepError names what is wrong."""
    parts = text.strip().split("-", 2)
    if len(parts) < 2 or parts[0] not in METHODS or parts[1] not in COMMS:
        raise SweepError(f"configuration '{text}' is not METHOD-COMM[-EPS] with METHOD in "
                         f"{'|'.join(METHODS)} and COMM in {'|'.join(COMMS)}")
    method, comm = parts[0], parts[1]
    eps = parts[2] if len(parts) == 3 else ""
    if method == "sor" and eps not in EPS_VALUES:
        raise SweepError(f"configuration '{text}': sor needs a tolerance, one of {', '.join(EPS_VALUES)} "
                         "(e.g. sor-async-1e-3)")
    if method != "sor" and eps:
        raise SweepError(f"configuration '{text}': only sor takes a tolerance")
    return Config(method, comm, eps)


def parse_configs(text):
    configs = [parse_config(t) for t in text.split(",") if t.strip()]
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
    configs: tuple           # of Config
    driver_options: tuple    # options every run gets, besides the configuration
    description: str


def _sweep(name, driver, experiment, ranks, configs, options, description):
    return Sweep(name, driver, experiment, tuple(ranks), tuple(parse_config(c) for c in configs),
                 tuple(options), description)


# The paper's sweeps at the paper's sizes (for clusters) and their copies for this machine.
# Driver defaults are the paper's values (64^3 cells and 2 particles per rank, ACM 50 steps
# at dt 1.25e-5, SOR 10 steps at 6.25e-5, calibrated N_S, N_C = 20), so the cluster sweeps
# pass no size options.
SWEEPS = {
    "weak": _sweep("weak", "weak_scaling", "weak", powers_of_two(1, 8192), PAPER_CONFIGS, (),
                   "paper section 3.2: 64^3 cells and 2 particles per rank, 1 to 8192 ranks"),
    "strong": _sweep("strong", "strong_scaling", "strong", powers_of_two(1024, 8192), PAPER_CONFIGS,
                     ("--scale", "1"),
                     "paper section 3.3: 2048 x 1024 x 1024 cells, 16384 particles, 1024 to 8192 ranks"),
    # This machine: the same block per rank on 1 and 2 ranks, every method and mode.
    "local-weak": _sweep("local-weak", "weak_scaling", "weak", (1, 2), ALL_CONFIGS, (),
                         "paper weak block (64^3 per rank) on 1 and 2 ranks, every method and mode"),
    # The strong case divided by 16 per direction (128 x 64 x 64 cells, 4 particles).
    "local-strong": _sweep("local-strong", "strong_scaling", "strong", (1, 2), ALL_CONFIGS,
                           ("--scale", "16"),
                           "paper strong case / 16 per direction (128 x 64 x 64) on 1 and 2 ranks"),
    # The README's main job: both local sweeps with 3 measured steps each (a few minutes).
    "quick-weak": _sweep("quick-weak", "weak_scaling", "weak", (1, 2), ALL_CONFIGS, ("--steps", "3"),
                         "as local-weak, 3 measured steps (the README's quick campaign)"),
    "quick-strong": _sweep("quick-strong", "strong_scaling", "strong", (1, 2), ALL_CONFIGS,
                           ("--scale", "16", "--steps", "3"),
                           "as local-strong, 3 measured steps (the README's quick campaign)"),
    # A few seconds in all: the JUBE test and a smoke run of the whole chain.  The block stays
    # the paper's (a smaller one no longer holds the 3.6-long particle lattice cell).
    "mini": _sweep("mini", "weak_scaling", "weak", (1, 2), ("acm-sync", "sor-async-1e-3"),
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
