#!/usr/bin/env bash
# The main job: set up, build, and run identify on the default config.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/build.sh"
mkdir -p "$root/results/main"
"$build_dir/identify/identify" simulate "$root/configs/paper_bar.yaml" \
  --output "$root/results/main/paper_bar_measurements.csv"
