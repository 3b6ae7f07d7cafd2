#!/usr/bin/env bash
# Installs the Debian packages physval builds and runs with, where missing.
# Run as root on Debian bookworm (the README's two commands call it).
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
