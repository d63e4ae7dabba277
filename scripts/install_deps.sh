#!/usr/bin/env bash
# Installs the Debian packages vesselverify needs, only those that are missing (idempotent).
# Fast when everything is already there: one dpkg-query per package, no network.
# Usage: scripts/install_deps.sh [extra-package ...]   (e.g. scripts/fuzz.sh adds clang)
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  ccache                                  # compiler cache: rebuilds and fresh clones reuse objects
  mold                                    # fast linker (cmake/fast_linker.cmake)
  libeigen3-dev libsuitesparse-dev        # msm: Eigen, CHOLMOD
  libopenblas0-pthread                    # BLAS for CHOLMOD, UMFPACK, eigen-solves (4x faster)
  libgmsh-dev                             # meshes: gmsh C++ API
  libdeal.ii-dev                          # fem_reference
  libgtest-dev libgmock-dev libbenchmark-dev
  libcli11-dev nlohmann-json3-dev libtomlplusplus-dev
  libspectra-dev
  libboost-dev                            # rod_theory: Boost.Math elliptic integrals, Odeint
  openmpi-bin                             # mpirun: fem --distributed, the reference job, their tests
  time                                    # /usr/bin/time: peak memory per rank (measure_cluster_scaling.py)
  calculix-ccx                            # CalculiX: the reference side by side with a peer (calculix_side_by_side.py)
  munge slurmctld slurmd slurm-client     # a one-node Slurm cluster for the sbatch test (slurm_localhost.sh)
  python3-matplotlib python3-numpy        # reports (use /usr/bin/python3)
  libjs-three libjs-chart.js              # report.html: 3D views and plots, inlined when written
  "$@"
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [ "$status" = "installed" ] || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

echo "install_deps: installing ${#missing[@]} missing Debian package(s): ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install_deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
