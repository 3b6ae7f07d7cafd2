#!/usr/bin/env bash
# Builds physval twice and runs every test in each build:
#   build/       Release, with the benchmarks compiled (not run)
#   build-asan/  Debug with AddressSanitizer and UndefinedBehaviorSanitizer
# Installs missing Debian packages first (scripts/setup.sh; root needed for that).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
jobs=$(nproc 2>/dev/null || echo 2)

echo "== Release build and tests"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

echo "== Gate: core on the built-in suite, with its tight limits (JUnit: build/core-gate.xml)"
./build/physval gate validation/scenarios --engines core --quiet --out build/core-gate --junit build/core-gate.xml

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DPHYSVAL_SANITIZE=ON -DPHYSVAL_BENCHMARKS=OFF >/dev/null
cmake --build build-asan -j "$jobs"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j "$jobs"
