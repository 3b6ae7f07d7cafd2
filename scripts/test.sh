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

echo "== Fuzz the scenario loader for ${PHYSVAL_FUZZ_SECONDS:-60} s (clang, libFuzzer, ASan, UBSan)"
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
  -DPHYSVAL_FUZZ=ON -DPHYSVAL_TESTS=OFF -DPHYSVAL_BENCHMARKS=OFF >/dev/null
cmake --build build-fuzz -j "$jobs" --target physval_fuzz_scenario_loader
rm -rf build-fuzz/corpus && mkdir -p build-fuzz/corpus build-fuzz/crashes
find validation/scenarios -name '*.toml' -exec cp {} build-fuzz/corpus/ \;
cp validation/fuzz/regressions/*.toml build-fuzz/corpus/
# A crash, leak or broken invariant fails the script; its input is in build-fuzz/crashes/.
./build-fuzz/validation/fuzz/physval_fuzz_scenario_loader build-fuzz/corpus \
  -max_total_time="${PHYSVAL_FUZZ_SECONDS:-60}" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix=build-fuzz/crashes/ -print_final_stats=1 2>build-fuzz/fuzz.log || {
  tail -40 build-fuzz/fuzz.log
  echo "fuzzer found a failing input: see build-fuzz/crashes/ (fix it, then keep it in validation/fuzz/regressions/)" >&2
  exit 1
}
grep -E "stat::number_of_executed_units|stat::peak_rss_mb" build-fuzz/fuzz.log || true

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests"
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DPHYSVAL_SANITIZE=ON -DPHYSVAL_BENCHMARKS=OFF >/dev/null
cmake --build build-asan -j "$jobs"
# intercept_tls_get_addr=0 is also compiled in (cmake/asan_default_options.cpp says why).
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-asan --output-on-failure -j "$jobs"
