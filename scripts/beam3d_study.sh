#!/usr/bin/env bash
# Regenerates results/beam3d/: the 3-D beam of configs/beam3d.yaml, one coupled solve's
# time per dof and step and its memory as the mesh grows to 21168 dofs, against the 2-D
# plates, and its four zones identified (scripts/beam3d_study.py), then identified on the
# 21168-dof mesh from a 3528-dof mesh's moduli (scripts/beam3d_fine_study.py, results/
# beam3d/fine); then results/README.md is gathered again. Needs SfePy (Debian's
# python3-sfepy) for the meshes, which are written to a temporary folder; about 1 h on
# one core.
# Usage: scripts/beam3d_study.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/build.sh" > /dev/null
/usr/bin/python3 "$root/scripts/beam3d_study.py" "$build_dir" "$root/results/beam3d"
/usr/bin/python3 "$root/scripts/beam3d_fine_study.py" "$build_dir" "$root/results/beam3d"
"$build_dir/identify/identify" study "$root/configs/studies.yaml" --output "$root/results" \
  --set study.kind=readme
