#!/usr/bin/env bash
# The main job: set up, build, and identify E on the paper's case
# (configs/paper_bar.yaml, SNR 2.5); results in results/main (summary.yaml, CSV
# files and figures). About 3 s after the build.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/build.sh"
cd "$root"
"$build_dir/identify/identify" run configs/paper_bar.yaml --output results/main
