#!/usr/bin/env bash
# Regenerates results/weights/: how the MCRE weights w_u, w_f change the
# conditioning of the coupled problem and the identification on the paper's case
# (weights.csv, cost_curves.csv, cost_curves.png). About 5 minutes on 2 cores.
# Usage: scripts/weights_study.sh [seeds]     (default 4 noise seeds at SNR 2.5)
#        scripts/weights_study.sh --plot-only  (redraw the figure from the CSVs)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"
out="$root/results/weights"

if [ "${1:-}" != "--plot-only" ]; then
  bash "$root/scripts/build.sh" > /dev/null
  mkdir -p "$out"
  "$build_dir/bench/weights_benchmark" "$out" "${1:-4}"
fi

# Normalised cost curves e^2 / min e^2 of noise seed 1 at SNR 2.5, one per weight pair.
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
plots=()
for pair in 0.001,1 0.01,1 0.1,1 1,1 0.01,0.1 0.01,10; do
  w_u="${pair%,*}"; w_f="${pair#*,}"
  awk -F, -v wu="$w_u" -v wf="$w_f" \
    'NR > 1 && $1 == wu && $2 == wf && $3 == 1 { e[++n] = $4; c[n] = $5; if (n == 1 || $5 < m) m = $5 }
     END { for (i = 1; i <= n; ++i) print e[i], c[i] / m }' "$out/cost_curves.csv" > "$work/$pair.dat"
  plots+=("'$work/$pair.dat' using 1:2 with linespoints title 'w_u = $w_u, w_f = $w_f'")
done
plot_list="$(IFS=,; echo "${plots[*]}")"
gnuplot <<GNUPLOT
set terminal pngcairo size 900,600 font ",11"
set output "$out/cost_curves.png.tmp"
set title "Cost curves on the paper's case, SNR 2.5 (seed 1), data from the 4x finer truth"
set xlabel "E / E_{ref}"
set ylabel "e^2(E) / min e^2"
set key top center
set yrange [*:*]
set grid
plot $plot_list
GNUPLOT
mv "$out/cost_curves.png.tmp" "$out/cost_curves.png"
{
  echo "## MCRE weights (\`weights/\`)"
  echo
  echo "How w_u and w_f change the conditioning and the identification on the paper's case"
  echo "(docs/weights.md): \`weights.csv\` per weight pair (a_max of A = I - G, CG and adaptive"
  echo "sweeps at E_ref, noise-free error, errors and sampled local minima over the SNR 2.5 seeds,"
  echo "relative curvature of e^2); \`cost_curves.png\`: e^2 / min e^2 of seed 1 at SNR 2.5."
  echo "Written by \`scripts/weights_study.sh\`."
  echo
  awk -F, 'NR == 1 { printf "|"; for (i = 1; i <= NF; ++i) printf " %s |", $i; printf "\n|";
                     for (i = 1; i <= NF; ++i) printf "---|"; printf "\n"; next }
           { printf "|"; for (i = 1; i <= NF; ++i) printf " %s |", $i; printf "\n" }' "$out/weights.csv"
  echo
} > "$out/summary.md.tmp"
mv "$out/summary.md.tmp" "$out/summary.md"
echo "wrote $out/weights.csv, cost_curves.csv, cost_curves.png"
