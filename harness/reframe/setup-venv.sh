#!/usr/bin/env bash
# Creates harness/reframe/.venv (git-ignored) with the pinned ReFrame from PyPI; Debian 12
# has no reframe package.  Does nothing when the venv already holds that version.
#   harness/reframe/setup-venv.sh [VENV_DIR]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="${1:-$here/.venv}"
want="$(sed -n 's/^reframe-hpc==//p' "$here/requirements.txt")"
if [ -x "$venv/bin/reframe" ] && [ "$("$venv/bin/reframe" --version 2>/dev/null)" = "$want" ]; then
  exit 0
fi
# Debian's python3 (python3-venv): another python3 may come first on PATH.
py=/usr/bin/python3
[ -x "$py" ] || py="$(command -v python3)"
echo "creating $venv with reframe-hpc $want"
"$py" -m venv "$venv"
"$venv/bin/pip" install --quiet --disable-pip-version-check -r "$here/requirements.txt"
got="$("$venv/bin/reframe" --version)"
[ "$got" = "$want" ] || { echo "setup-venv.sh: error: $venv has reframe $got, not $want" >&2; exit 1; }
