#!/usr/bin/env bash
# Builds mcrewave (scripts/build.sh) and regenerates every study of issue 6 and its
# figures into results/ with `identify study configs/studies.yaml` (include/mcrewave/study.h):
# results/robustness/, results/relaxation/, results/cost_curves/ (CSV files, PNG figures,
# summary.md each) and results/README.md (the summaries: what each figure shows, the
# headline numbers). results/weights, results/complexity and results/robustness_settings
# come from their own scripts and are left as they are.
# Usage: scripts/studies.sh [--set key.path=value]...   e.g. --set study.kind=relaxation
#        (the robustness study at its default 401 identifications takes most of the time)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/build.sh" > /dev/null
cd "$root"
"$build_dir/identify/identify" study configs/studies.yaml --output results "$@"
