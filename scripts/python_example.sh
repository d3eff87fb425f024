#!/usr/bin/env bash
# Regenerates results/python_example/: examples/plate_with_sfepy.py, a plate assembled by
# SfePy and its 8 zones identified through the Python module, with its modulus and error
# maps (maps.png) and zones.csv (docs/python.md section 5; about 15 s on one core).
# Installs Debian's python3-sfepy and python3-matplotlib when missing.
# Usage: scripts/python_example.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/install_dependencies.sh" python3-sfepy python3-matplotlib
bash "$root/scripts/build.sh" > /dev/null
PYTHONPATH="$build_dir" /usr/bin/python3 "$root/examples/plate_with_sfepy.py" \
  --output "$root/results/python_example"
