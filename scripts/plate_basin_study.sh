#!/usr/bin/env bash
# Regenerates results/plate_basin/: the basin of attraction of the MCRE and of least
# squares on the 8 zones of the SfePy plate of examples/plate_with_sfepy.py, from the
# truth and from 8 homogeneous starts 0.5 E to 2 E (scripts/plate_basin_study.py;
# docs/matrix_models.md section 17; about 45 s on one core). Installs Debian's
# python3-sfepy and python3-matplotlib when missing; then results/README.md is gathered
# again.
# Usage: scripts/plate_basin_study.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/install_dependencies.sh" python3-sfepy python3-matplotlib
bash "$root/scripts/build.sh" > /dev/null
PYTHONPATH="$build_dir" /usr/bin/python3 "$root/scripts/plate_basin_study.py" \
  "$root/results/plate_basin"
"$build_dir/identify/identify" study "$root/configs/studies.yaml" --output "$root/results" \
  --set study.kind=readme
