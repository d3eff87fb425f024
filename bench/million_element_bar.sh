#!/usr/bin/env bash
# The paper's bar with 1e6 elements identified at the defaults on one core
# (docs/multilevel.md section 4): the data simulated once on 1e6 elements (truth on 4e6
# elements and 7000 steps, about 8 min), then `identify run` on them, from a coarse mesh
# of model.coarse_elements up the ladder of meshes, pinned to one core. Prints the
# identification's wall time, peak memory and E; everything is written under FOLDER
# (default build/million_element_bar; its error_map.csv holds 1e6 rows).
# Usage: bench/million_element_bar.sh [FOLDER] [--set key=value ...]
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"
folder="$build_dir/million_element_bar"
if [[ $# -gt 0 && "$1" != --* ]]; then
  folder="$1"
  shift
fi
identify="$build_dir/identify/identify"
config="$root/configs/paper_bar.yaml"
mkdir -p "$folder"
if [[ ! -s "$folder/data.csv" ]]; then
  echo "simulating the data on 1e6 elements into $folder/data.csv"
  "$identify" simulate "$config" --set model.elements=1000000 -q -o "$folder/data.csv"
fi
echo "identifying on 1e6 elements, one core (progress in $folder/run.log)"
taskset -c 0 /usr/bin/time -v "$identify" run "$config" --set model.elements=1000000 \
  --set data.source=csv --set data.path="$folder/data.csv" --set output.folder="$folder/run" \
  "$@" > "$folder/run.log" 2>&1
grep -E "Elapsed|Maximum resident" "$folder/run.log"
grep -E "^identified_modulus|^wall_time_s|^evaluations" "$folder/run/summary.yaml"
sed -n '/^coarse_mesh:/,/refinement_wall_time_s/p' "$folder/run/summary.yaml"
