#!/usr/bin/env bash
# Installs the Debian packages physval builds and runs with, where missing.
# Run as root on Debian bookworm (the README's two commands call it).
#   scripts/setup.sh           what physval builds and runs with
#   scripts/setup.sh --slurm   only the one-node Slurm cluster of scripts/test-slurm.sh
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config git
  libbox2d-dev libbullet-dev libeigen3-dev libchipmunk-dev libode-dev
  libtomlplusplus-dev nlohmann-json3-dev libcli11-dev
  libgtest-dev libbenchmark-dev
  gnuplot-nox zlib1g-dev chromium
  python3
  clang-14 libclang-rt-14-dev
)
if [ "${1:-}" = --slurm ]; then
  # slurmctld, slurmd and their clients (sbatch, sinfo), munge for authentication;
  # python3 compares the results. Nothing here is needed to build or run physval.
  packages=(slurmctld slurmd slurm-client munge python3)
elif [ -n "${1:-}" ]; then
  echo "setup: unknown option $1 (none, or --slurm)" >&2
  exit 2
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  if [ "$(id -u)" != 0 ]; then
    echo "setup: these Debian packages are missing and installing them needs root: ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
