#!/usr/bin/env bash
# Regenerates results/plate_zones_basin/: the basin of attraction of the MCRE and of least
# squares on the 64 zones of the many-zone plate (the soft inclusion) from full-field data
# at SNR 10 (configs/plate_zones.yaml; full_field/) and from 20 strain gauges at SNR 20
# (configs/plate_zones_gauges.yaml; gauges/): from the truth and from 8 homogeneous starts
# 0.5 E to 2 E, each functional at the weight its rule keeps from the truth, then
# continuation in the data weight (scripts/plate_zones_basin_study.py;
# docs/matrix_models.md section 17). The two functionals run side by side, one process
# each: about 30 minutes a case on two cores. Then results/README.md is gathered again.
# Arguments go to the Python script, e.g. `--case gauges`.
# Usage: scripts/plate_zones_basin_study.sh [--case full_field|gauges|both]
#        [--functional mcre|least_squares|both | --continuation-only | --figures-only]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/build.sh" > /dev/null
/usr/bin/python3 "$root/scripts/plate_zones_basin_study.py" "$build_dir" \
  "$root/results/plate_zones_basin" "$@"
"$build_dir/identify/identify" study "$root/configs/studies.yaml" --output "$root/results" \
  --set study.kind=readme
