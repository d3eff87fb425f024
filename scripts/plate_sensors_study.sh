#!/usr/bin/env bash
# Regenerates results/plate_sensors/: sensor layouts for the many-zone plate
# (configs/plate_zones.yaml, the soft inclusion, SNR 20) chosen by `identify sensors`,
# their Cramer-Rao standard deviations per zone, and the 64 zones identified from the
# hand-placed ten sensors and from 20 chosen strain gauges
# (scripts/plate_sensors_study.py: designs.csv, runs.csv, summary.md, cramer_rao.png);
# then results/README.md is gathered again. The designs take seconds, each
# identification several minutes on one core. `--designs-only` skips the
# identifications.
# Usage: scripts/plate_sensors_study.sh [--designs-only]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/build.sh" > /dev/null
/usr/bin/python3 "$root/scripts/plate_sensors_study.py" "$build_dir" "$root/results/plate_sensors" "$@"
"$build_dir/identify/identify" study "$root/configs/studies.yaml" --output "$root/results" \
  --set study.kind=readme
