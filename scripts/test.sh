#!/usr/bin/env bash
# Set up, build, and run the whole test suite with ctest; then build it again
# with AddressSanitizer + UndefinedBehaviorSanitizer (clang, into build-sanitize/
# or $MCREWAVE_SANITIZE_BUILD_DIR), run it there, and fuzz each of the four readers for
# $MCREWAVE_FUZZ_SECONDS (default 15) seconds (fuzz/README.md).
# The benchmarks are compiled in the first build (so that bench/ cannot break
# unnoticed) but not run (scripts/main.sh and the study scripts run them); the
# sanitizer build leaves them out, as no test runs them. The sanitizer build is
# optimised at -O1 (faster to compile; its tests check memory and undefined
# behaviour, the Release pass checks the numbers), keeps the library's asserts (no
# NDEBUG: the one pass where they run), and tests labelled `long` are left out of it
# (see tests/CMakeLists.txt).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"
sanitize_dir="${MCREWAVE_SANITIZE_BUILD_DIR:-$root/build-sanitize}"

bash "$root/scripts/build.sh"
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)"

cmake -S "$root" -B "$sanitize_dir" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS_RELEASE="-O1" -DCMAKE_CXX_COMPILER=clang++ -DMCREWAVE_BUILD_FUZZERS=ON \
  -DMCREWAVE_BUILD_BENCHMARKS=OFF
cmake --build "$sanitize_dir" -j "$(nproc)"
# A sanitizer report exits with 86 (ASan) or 87 (UBSan), codes no test expects, so a
# report in an identify run whose test expects a failure still fails it.
export ASAN_OPTIONS=exitcode=86
export UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1:exitcode=87
ctest --test-dir "$sanitize_dir" --output-on-failure -j "$(nproc)" --label-exclude long
bash "$root/scripts/fuzz.sh" "$sanitize_dir" "${MCREWAVE_FUZZ_SECONDS:-15}"
