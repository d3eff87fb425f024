#!/usr/bin/env bash
# Runs each libFuzzer target of fuzz/ for a bounded time on a copy of its seed
# corpus (fuzz/corpus/<name>/), inside a build configured with
# -DMCREWAVE_BUILD_FUZZERS=ON. Fails on the first crash, hang, leak or sanitizer
# report; the input that caused it is left in BUILD_DIR/fuzz_artifacts/.
#   bash scripts/fuzz.sh BUILD_DIR [SECONDS_PER_TARGET (default 30)]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$1"
seconds="${2:-30}"

export ASAN_OPTIONS="${ASAN_OPTIONS:-exitcode=86}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1:exitcode=87}"
mkdir -p "$build_dir/fuzz_artifacts"
for target in config:config_fuzzer csv:measurement_csv_fuzzer \
    matrix_market:matrix_market_fuzzer manifest:model_manifest_fuzzer; do
  corpus="${target%%:*}"
  binary="$build_dir/fuzz/${target#*:}"
  work="$build_dir/fuzz_corpus/$corpus"
  mkdir -p "$work"
  echo "mcrewave: fuzzing ${target#*:} for ${seconds} s"
  log="$build_dir/fuzz_artifacts/${target#*:}.log"
  if ! "$binary" "$work" "$root/fuzz/corpus/$corpus" -max_total_time="$seconds" -timeout=10 \
      -rss_limit_mb=2048 -max_len=8192 -print_final_stats=1 \
      -artifact_prefix="$build_dir/fuzz_artifacts/" >"$log" 2>&1; then
    tail -n 80 "$log"
    echo "mcrewave: ${target#*:} found a defect; the input is in $build_dir/fuzz_artifacts/" >&2
    exit 1
  fi
  grep -E '^stat::(number_of_executed_units|peak_rss_mb)' "$log"
done
