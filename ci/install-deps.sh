#!/usr/bin/env bash
# Installs the Debian 12 packages EFSI-Bench builds and runs with, only those missing.
set -euo pipefail

packages=(
  g++ cmake make pkg-config          # toolchain
  libopenmpi-dev openmpi-bin         # MPI
  libfftw3-dev                       # FFTW3 (double, with libfftw3_omp)
  libhypre-dev                       # hypre: the multigrid pressure method
  libhdf5-openmpi-dev                # parallel HDF5: snapshots and checkpoints
  libcli11-dev                       # command lines
  libgtest-dev googletest            # tests
  libbenchmark-dev                   # micro-benchmarks
  valgrind                           # the CI gate's counted work (callgrind)
  python3 python3-matplotlib         # plots (Debian's python3 at /usr/bin/python3)
  python3-h5py python3-skimage       # reading snapshots; phi = 1/2 surfaces (marching cubes)
  python3-scipy                      # the particles as labelled regions (their shapes)
  jube                               # cluster benchmark definitions
  slurmctld slurmd slurm-client munge  # the local one-node SLURM cluster (harness/slurm-local)
  python3-venv                       # the ReFrame venv (harness/reframe/setup-venv.sh)
  libsimgrid-dev                     # SimGrid's SMPI: the simulation build (harness/simgrid)
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

echo "installing: ${missing[*]}"
sudo=""
[ "$(id -u)" -ne 0 ] && sudo="sudo"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}"
