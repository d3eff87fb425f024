#!/usr/bin/env bash
# Regenerates results/complexity/: the MACs and seconds of every coupled solver on
# the paper's case against the number of degrees of freedom n (the paper's Table 1
# and Fig. 5), measured with bench/complexity_benchmark.cpp (methods.csv,
# paper_table1.csv, exponents.csv, shooting_breakdown.csv, summary.txt) and plotted
# in complexity.png. A few minutes on 2 cores.
# Usage: scripts/complexity_study.sh [max_dofs]   (default 1000)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"
out="$root/results/complexity"

if [[ ! -x "$build_dir/bench/complexity_benchmark" ]]; then
  bash "$root/scripts/build.sh" > /dev/null
else
  cmake --build "$build_dir" -j "$(nproc)" --target complexity_benchmark > /dev/null
fi
mkdir -p "$out"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$build_dir/bench/complexity_benchmark" "$out" "${1:-1000}" | tee "$work/summary.txt"
mv "$work/summary.txt" "$out/summary.txt.tmp"
mv "$out/summary.txt.tmp" "$out/summary.txt"

# One data file per method (dofs, MACs, seconds), then the paper's formulas.
methods=(relaxation_fixed_omega adaptive_relaxation conjugate_gradient all_at_once riccati
         single_shooting multiple_shooting)
titles=("relaxation, fixed omega" "adaptive relaxation" "conjugate gradients (Krylov)"
        "all-at-once (sparse LU)" "Riccati" "single shooting" "multiple shooting")
macs_plots=()
seconds_plots=()
for i in "${!methods[@]}"; do
  method="${methods[$i]}"
  awk -F, -v method="$method" 'NR > 1 && $1 == method { print $2, $5, $6 }' \
    "$out/methods.csv" > "$work/$method.dat"
  [[ -s "$work/$method.dat" ]] || continue
  style="with linespoints lw 2 pt $((i + 4)) lc $((i + 1)) title '${titles[$i]}'"
  if [[ "$method" != all_at_once ]]; then
    macs_plots+=("'$work/$method.dat' using 1:2 $style")
  fi
  seconds_plots+=("'$work/$method.dat' using 1:3 $style")
done
awk -F, 'NR > 1 { print $1, $4, $5, $6 }' "$out/paper_table1.csv" > "$work/paper.dat"
macs_plots+=("'$work/paper.dat' using 1:2 with lines dt 2 lw 2 lc 5 title 'paper: Riccati'")
macs_plots+=("'$work/paper.dat' using 1:3 with lines dt 2 lw 2 lc 6 title 'paper: shooting'")
macs_plots+=("'$work/paper.dat' using 1:4 with lines dt 2 lw 2 lc 1 title 'paper: relaxation (our k)'")
macs_list="$(IFS=,; echo "${macs_plots[*]}")"
seconds_list="$(IFS=,; echo "${seconds_plots[*]}")"

gnuplot <<GNUPLOT
set terminal pngcairo size 1500,650 font ",11"
set output "$out/complexity.png.tmp"
set multiplot layout 1,2 title "Cost of one coupled solve on the paper's case (1750 steps, theta = 1/2, w_u = 0.01, w_f = 1, tolerance 1e-8)"
set logscale xy
set grid
set format y "10^{%L}"
set xlabel "degrees of freedom n"
set key top left font ",9"
set title "multiply-accumulates (dashed: the paper's Table 1)"
set ylabel "MACs"
plot $macs_list
set title "wall time, one core"
set ylabel "seconds"
plot $seconds_list
unset multiplot
GNUPLOT
mv "$out/complexity.png.tmp" "$out/complexity.png"
{
  echo "## Complexity of the coupled solvers (\`complexity/\`)"
  echo
  echo "\`complexity.png\` (the paper's Fig. 5): multiply-accumulates and seconds of one coupled"
  echo "solve against the degrees of freedom n for every solver, the paper's Table 1 formulas"
  echo "dashed; rows marked 'extrapolated' were timed on fewer steps and scaled."
  echo "\`methods.csv\`: one row per method and n; \`exponents.csv\`: fitted growth exponents;"
  echo "\`paper_table1.csv\`: the paper's formulas; \`shooting_breakdown.csv\`: single shooting"
  echo "as the window grows (docs/riccati_shooting.md). Written by \`scripts/complexity_study.sh\`."
  echo
  echo '```'
  cat "$out/summary.txt"
  echo '```'
  echo
} > "$out/summary.md.tmp"
mv "$out/summary.md.tmp" "$out/summary.md"
echo "wrote $out/{methods,paper_table1,exponents,shooting_breakdown}.csv, summary.txt, complexity.png"
