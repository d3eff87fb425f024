#!/usr/bin/env bash
# Regenerates results/real/: the bars' modulus from both real Hopkinson-bar shots of
# configs/shpb/data with the striker's and the specimen's forces unmeasured, the rod
# model against a Rayleigh-Love rod and against the documented bar length, figures of
# the gauges, the identified forces, e^2 against E and the error map along the bars
# (scripts/shpb_study.py; numpy and gnuplot; about 5 min on one core). Then
# results/README.md is gathered again.
# Usage: scripts/shpb_study.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/build.sh" > /dev/null
/usr/bin/python3 "$root/scripts/shpb_study.py" "$build_dir" "$root/results/real"
"$build_dir/identify/identify" study "$root/configs/studies.yaml" --output "$root/results" \
  --set study.kind=readme
