#!/usr/bin/python3
"""Writes the diagnostics series and the centroids that a checkpoint carries as CSV files
(series-METHOD.csv, centroids-METHOD.csv in --out), byte for byte as the driver would have
written them at the checkpoint's step.  A run that blows up or is killed records nothing as
valid, so its last checkpoint is where its history up to that step survives.

  checkpoint_history.py --out results/accuracy-128 RUN/ck-acm.h5

Bad input or a failed write: one line on standard error, exit status 2 (usage) or 1 (a file),
and no file left under a final name that was not complete.  An existing CSV is kept unless
--force is given.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_plots import OneLineParser, UsageError  # noqa: E402

# The checkpoint's datasets of CSV text and the file each becomes (METHOD filled in).
STREAMS = (("series", "series-{}.csv"), ("centroids", "centroids-{}.csv"))


def read_history(path):
    """(method, step, time, {dataset: bytes}) of a checkpoint; OSError naming the file when it
    is not one."""
    import h5py
    try:
        with h5py.File(path, "r") as f:
            if "config method" not in f.attrs or "step" not in f.attrs:
                raise OSError(f"{path}: not a checkpoint (no 'config method' or 'step' attribute)")
            method = f.attrs["config method"]
            method = method.decode() if isinstance(method, bytes) else str(method)
            texts = {name: f[name][...].tobytes() if name in f else b"" for name, _ in STREAMS}
            return method, int(f.attrs["step"]), float(f.attrs["time"]), texts
    except OSError as e:
        raise OSError(str(e) if path in str(e) else f"{path}: {e}") from None


def write_all(pairs):
    """Writes every (target, bytes) pair under a temporary name first and renames them only
    when all are complete, so that a failure leaves none of them half written or alone."""
    done = []
    try:
        for target, data in pairs:
            tmp = target + ".tmp"
            done.append(tmp)
            with open(tmp, "wb") as f:
                f.write(data)
                f.flush()
                os.fsync(f.fileno())
    except OSError as e:
        for tmp in done:
            if os.path.lexists(tmp):
                os.remove(tmp)
        raise OSError(f"{done[-1][:-4]}: {e.strerror or e}") from None
    for target, _ in pairs:
        try:
            os.replace(target + ".tmp", target)
        except OSError as e:
            for tmp in done:
                if os.path.lexists(tmp):
                    os.remove(tmp)
            raise OSError(f"{target}: {e.strerror or e}") from None


def main(argv=None):
    p = OneLineParser(prog="checkpoint_history.py", description=__doc__.split("\n\n")[0])
    p.add_argument("checkpoint", help="a checkpoint written by --checkpoint")
    p.add_argument("--out", required=True, help="existing directory for the CSV files")
    p.add_argument("--method", help="name in the files (default: the checkpoint's method)")
    p.add_argument("--force", action="store_true", help="replace CSV files that exist")
    try:
        args = p.parse_args(argv)
        if not os.path.isfile(args.checkpoint):
            raise UsageError(f"no file {args.checkpoint}")
        if not os.path.isdir(args.out):
            raise UsageError(f"--out {args.out} is not an existing directory")
    except UsageError as e:
        print(f"checkpoint_history.py: error: {e}", file=sys.stderr)
        return 2
    try:
        method, step, time, texts = read_history(args.checkpoint)
    except OSError as e:
        print(f"checkpoint_history.py: error: {e}", file=sys.stderr)
        return 1
    method = args.method or method
    targets = [(os.path.join(args.out, pattern.format(method)), texts[name]) for name, pattern in STREAMS
               if texts[name]]
    if not targets:
        print(f"checkpoint_history.py: error: {args.checkpoint} holds no series and no centroids", file=sys.stderr)
        return 1
    for target, _ in targets:
        if os.path.isdir(target):
            print(f"checkpoint_history.py: error: {target} is a directory", file=sys.stderr)
            return 1
        if os.path.exists(target) and not args.force:
            print(f"checkpoint_history.py: error: {target} exists (--force replaces it)", file=sys.stderr)
            return 2
    try:
        write_all(targets)
    except OSError as e:
        print(f"checkpoint_history.py: error: {e}", file=sys.stderr)
        return 1
    for target, data in targets:
        rows = data.count(b"\n") - 1
        print(f"wrote {target} ({rows} rows, checkpoint step {step}, t = {time:g})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
