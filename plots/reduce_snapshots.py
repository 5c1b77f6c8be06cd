#!/usr/bin/python3
"""Keeps what the plots read of the drivers' HDF5 state files: phi, compressed, with the
file's attributes (snapshots.write_phi_only), one file per input under the same name in
--out; bit for bit unless --single or --zero-below reduce it further.  make_plots.py
--accuracy-dir DIR finds such files in DIR/phi/, so a run of one method in one session and
of the other in another can still be drawn and compared side by side.

  reduce_snapshots.py --out results/accuracy-128/phi --single --zero-below 1e-6 \
      RUN/snapshot-acm-000[0-4]0000.h5

Bad input or a failed write: one line on standard error, exit status 2 (usage) or 1 (a file),
and no file left under its final name for the input that failed.
"""

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import snapshots as sn  # noqa: E402
from make_plots import OneLineParser, UsageError  # noqa: E402


def main(argv=None):
    p = OneLineParser(prog="reduce_snapshots.py", description=__doc__.split("\n\n")[0])
    p.add_argument("snapshots", nargs="+", help="state files (snapshots, fields-METHOD.h5, checkpoints)")
    p.add_argument("--out", required=True, help="existing directory for the phi-only files")
    p.add_argument("--single", action="store_true", help="round phi to float32")
    p.add_argument("--zero-below", type=float, default=0.0, metavar="EPS",
                   help="set |phi| < EPS to 0 (default 0: none)")
    try:
        args = p.parse_args(argv)
        if not (0.0 <= args.zero_below < 0.5):
            raise UsageError(f"--zero-below {args.zero_below:g} is outside [0, 0.5)")
        if not os.path.isdir(args.out):
            raise UsageError(f"--out {args.out} is not an existing directory")
        for path in args.snapshots:
            if not os.path.isfile(path):
                raise UsageError(f"no file {path}")
    except UsageError as e:
        print(f"reduce_snapshots.py: error: {e}", file=sys.stderr)
        return 2
    for path in args.snapshots:
        target = os.path.join(args.out, os.path.basename(path))
        try:
            sn.write_phi_only(path, target, args.single, args.zero_below)
        except OSError as e:
            print(f"reduce_snapshots.py: error: {path} -> {target}: {e}", file=sys.stderr)
            return 1
        print(f"wrote {target} ({os.path.getsize(target)} bytes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
