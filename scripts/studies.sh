#!/usr/bin/env bash
# Builds mcrewave (scripts/build.sh) and regenerates every study and figure of
# results/, then results/README.md gathering their summary.md files:
#   results/robustness_settings/  bench/robustness_benchmark, 50 seeds (docs/robustness.md)
#   results/complexity/           scripts/complexity_study.sh (the paper's Table 1, Fig. 5)
#   results/weights/              scripts/weights_study.sh (docs/weights.md)
#   results/robustness/, cost_curves/  `identify study configs/studies.yaml` at the defaults
#                                 (the clamp trusted, docs/trusted_clamp.md)
#   results/relaxation/           the same in the paper's free-free formulation (its
#                                 omega study: at the defaults' small weights every
#                                 omega below 2 converges)
#   results/comparator/           `identify study configs/studies.yaml --set study.kind=comparator`
#                                 (MCRE against least squares, 100 seeds x 4 SNRs x 8 model
#                                 errors, springs at the clamp among them, on pre-filtered
#                                 data; about 35 minutes on 2 cores)
#   results/damage/               `identify study configs/studies.yaml --set study.kind=damage`
#                                 (include/mcrewave/app/study.h; about 26 minutes on 2 cores),
#                                 which writes results/README.md
# The first four parts take about 10 minutes on 2 cores. Arguments go to `identify study`, and with any of them
# only the identify studies run, e.g.
#   bash scripts/studies.sh --set study.kind=relaxation
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="${MCREWAVE_BUILD_DIR:-$root/build}"

bash "$root/scripts/build.sh" > /dev/null
cd "$root"
if [ "$#" -eq 0 ]; then
  mkdir -p results/robustness_settings
  "$build_dir/bench/robustness_benchmark" results/robustness_settings 50
  bash "$root/scripts/complexity_study.sh"
  bash "$root/scripts/weights_study.sh"
fi
if [ "$#" -ne 0 ]; then
  "$build_dir/identify/identify" study configs/studies.yaml --output results "$@"
else
  "$build_dir/identify/identify" study configs/studies.yaml --output results \
    --set study.kind=robustness
  "$build_dir/identify/identify" study configs/studies.yaml --output results \
    --set study.kind=cost_curves
  "$build_dir/identify/identify" study configs/studies.yaml --output results \
    --set study.kind=relaxation --set mcre.clamp=measured --set mcre.w_u=0.01
  "$build_dir/identify/identify" study configs/studies.yaml --output results \
    --set study.kind=comparator
  # The damage-localisation study (results/damage; zones and interior sensors), in the
  # free-free formulation its quick-case test checks, its scalar E* from a scan of that
  # e^2 itself (search.functional same): with the clamp trusted the
  # reaction's misfit puts the error map's peak at the clamp (0.02 m on the quick
  # case). The gauges' weight w_e = 1e-4, the lightest at which the error map points
  # at the soft zone: noise-free, 10 zones, every zone within 0.04 % in 33 s a run
  # (docs/zones_and_sensors.md, "The gauges' weight w_e"). Total variation, not the
  # default Tikhonov penalty: the truths are piecewise constant, and at SNR 10 every
  # other zone was within 5 % on 13 of 20 seeds against 0 of 6 ("Damage
  # localisation"). Neighbouring zones merged while a refit meets the noise's level
  # (10 equal zones; "Merging neighbouring zones"): at SNR 10 every other zone within
  # 5 % on 19 of 20 seeds against 13. The 10 equal zones are also fitted by least
  # squares with the same options ("Zones: the MCRE against least squares"). About
  # 26 min on 2 cores: the runs with interior sensors and one zone per element take 1
  # to 4 min each.
  "$build_dir/identify/identify" study configs/studies.yaml --output results \
    --set study.kind=damage --set mcre.clamp=measured --set mcre.w_u=0.01 --set mcre.w_e=1e-4 \
    --set search.functional=same --set zone_identification.regularization=total_variation \
    --set zone_identification.merge_zones=true
fi
