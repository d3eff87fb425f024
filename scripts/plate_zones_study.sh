#!/usr/bin/env bash
# Regenerates results/plate_zones/: the 64 zones of the many-zone plate
# (configs/plate_zones.yaml) identified by the MCRE and by least squares for five cases
# (the soft inclusion from full-field data at SNR 10 and 5 and from ten point sensors at
# SNR 10, two inclusions and a crack-like soft band from full-field data at SNR 10), each
# set against its truth (scripts/plate_zones_study.py: cases.csv, summary.md, a maps.png
# per case), then refits the zones the soft inclusion's error map flags against one
# background modulus (update.csv, about 4 minutes) and then every element of those zones
# against it at SNR 10 and 5 (element_update.csv and .png, about 12 minutes), and every
# element of the plate (per_element.csv and .png, about 17 minutes; by least squares,
# per_element_least_squares.csv and .png, its gradient by the adjoint); then results/README.md
# is gathered again. About 110 minutes on one core (an
# MCRE run about 8 minutes, half of it the 64 zones' curvature for the uncertainty; a
# least-squares run about 6). Arguments go to the Python script, e.g.
# `--functional least_squares` to run that functional alone.
# Usage: scripts/plate_zones_study.sh [--functional mcre|least_squares|both | --update-only |
#        --element-update-only | --per-element-only [--functional mcre|least_squares|both]]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/build.sh" > /dev/null
/usr/bin/python3 "$root/scripts/plate_zones_study.py" "$build_dir" "$root/results/plate_zones" "$@"
"$build_dir/identify/identify" study "$root/configs/studies.yaml" --output "$root/results" \
  --set study.kind=readme
