#!/usr/bin/env bash
# Regenerates results/plate/: the plate example (docs/matrix_models.md) identified by
# the MCRE, both zone moduli at SNR inf, 20 and 10 over noise seeds, and the error map
# over the mesh (bench/plate_identification_benchmark.cpp). The model is the committed
# 48 x 12 mesh (configs/plate/fine, 1248 dofs); the truth a 96 x 24 mesh (4800 dofs)
# made here by scripts/make_plate_example.py into a temporary folder (Debian's
# python3-numpy, installed here when missing; the build and the tests never need it);
# an axial impact on the free edge; then results/README.md is gathered again.
# About 20 minutes on 2 idle cores with 20 seeds.
# Usage: scripts/plate_study.sh [seeds]     (default 20)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"
out="$root/results/plate"

bash "$root/scripts/install_dependencies.sh" python3-numpy
bash "$root/scripts/build.sh" > /dev/null
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 "$root/scripts/make_plate_example.py" --nx 48 --ny 12 --refine 2 \
  --output "$work" > /dev/null
mkdir -p "$out"
"$build_dir/bench/plate_identification_benchmark" "$out" --seeds="${1:-20}" --load=axial \
  --model="$root/configs/plate/fine" --truth="$work/fine"
"$build_dir/identify/identify" study "$root/configs/studies.yaml" --output "$root/results" \
  --set study.kind=readme
