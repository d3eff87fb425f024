#!/usr/bin/env python3
"""Regenerates results/plate_zones/: the 64 zones of the many-zone plate
(configs/plate_zones.yaml, configs/plate_zones/README.md) identified by the MCRE for each
case of CASES (truth, sensor set, SNR), and each run's zones set against its truth.

For every case, `identify run configs/plate_zones.yaml` with the case's truth, manifest
and SNR (the cost curve at 5 points, no figures of its own) into a temporary folder; its
zones.csv and error_map.csv are kept in results/plate_zones/<case>/. Then, per case:

  - the truth of each zone: the moduli of the truth's fine elements whose model element
    lies in the zone, combined in series (1 / E = mean of 1 / E_el, the Reuss bound) and
    in parallel (mean of E_el, the Voigt bound); a zone is 'changed' when its series
    modulus differs from 200 GPa by more than 0.1 %;
  - localisation: of the k changed zones, how many are among the k zones farthest from
    the homogeneous E* (|ln E_z / E*|), and how many among the k largest shares of the
    error map at the nominal moduli (zones.csv error_share_nominal); whether the map's
    peak is a changed zone;
  - sizing: the changed zones' worst relative error against the series truth (and
    whether E lies between the two bounds), the other zones' worst and rms error.

Writes cases.csv (a row per case), summary.md, and <case>/maps.png: the truth (series),
the identified moduli and the error map's share per zone at the nominal moduli, on the
16 x 4 grid (gnuplot). Prints progress; the files are written atomically.

Usage: /usr/bin/python3 scripts/plate_zones_study.py BUILD_DIR RESULTS_DIR [--figures-only]
       (--figures-only: no run; each case's maps.png drawn again from its kept zones.csv)
"""

import csv
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plate_zones_geometry import (HEIGHT, LENGTH, MODEL_ELEMENTS, NOMINAL_MODULUS,  # noqa: E402
                                  REFINE, TRUTHS)

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
GRID = (16, 4)  # configs/plate_zones.yaml's model.zone_grid
CASES = [  # (truth, manifest, SNR)
    ("soft_inclusion", "full_field", 10),
    ("soft_inclusion", "full_field", 5),
    ("soft_inclusion", "points", 10),
    ("two_inclusions", "full_field", 10),
    ("soft_band", "full_field", 10),
]
CHANGED = 1e-3


def case_name(truth, manifest, snr):
    return f"{truth}_{manifest}_snr{snr:g}"


def write_atomic(path, text):
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def truth_of_zones(truth):
    """Per zone name grid_i_j: (series, parallel) moduli relative to NOMINAL_MODULUS of
    the truth's fine elements under the zone's model elements."""
    nx, ny = MODEL_ELEMENTS
    fine_dx, fine_dy = LENGTH / (nx * REFINE), HEIGHT / (ny * REFINE)
    moduli = {}
    for j in range(ny):
        for i in range(nx):
            # The model element's box (RegroupedElementZones: centroids over their extent).
            zx = min(GRID[0] - 1, int(i / (nx - 1) * GRID[0]))
            zy = min(GRID[1] - 1, int(j / (ny - 1) * GRID[1]))
            zone = moduli.setdefault(f"grid_{zx}_{zy}", [])
            for a in range(REFINE):
                for b in range(REFINE):
                    x = (i * REFINE + a + 0.5) * fine_dx
                    y = (j * REFINE + b + 0.5) * fine_dy
                    value = 1.0
                    for _, modulus, inside in TRUTHS[truth]:
                        if inside(x, y):
                            value = modulus
                    zone.append(value)
    return {name: (len(m) / sum(1.0 / v for v in m), sum(m) / len(m))
            for name, m in moduli.items()}


def run_case(build_dir, work, truth, manifest, snr):
    moduli = [1.0] + [modulus for _, modulus, _ in TRUTHS[truth]]
    folder = os.path.join(work, case_name(truth, manifest, snr))
    command = [os.path.join(build_dir, "identify", "identify"), "run",
               os.path.join(ROOT, "configs", "plate_zones.yaml"),
               "--set", f"model.manifest=plate_zones/model/{manifest}.yaml",
               "--set", f"data.truth_manifest=plate_zones/truth/{truth}.yaml",
               "--set", "data.truth_moduli=[" +
               ",".join(f"{m * NOMINAL_MODULUS:.17g}" for m in moduli) + "]",
               "--set", f"data.snr={snr:g}", "--set", "output.curve_points=5",
               "--set", "output.figures=false", "-q", "-o", folder]
    start = time.monotonic()
    subprocess.run(command, check=True)
    return folder, time.monotonic() - start


def analyse(zones_csv, truth):
    rows = list(csv.DictReader(open(zones_csv)))
    truths = truth_of_zones(truth)
    homogeneous = math.exp(sum(math.log(float(r["modulus_pa"])) for r in rows) / len(rows))
    zones = []
    for r in rows:
        series, parallel = truths[r["name"]]
        zones.append({"name": r["name"], "E": float(r["modulus_pa"]) / NOMINAL_MODULUS,
                      "series": series, "parallel": parallel,
                      "share": float(r["error_share_nominal"]),
                      "distance": abs(math.log(float(r["modulus_pa"]) / homogeneous))})
    changed = [z for z in zones if abs(z["series"] - 1.0) > CHANGED]
    others = [z for z in zones if abs(z["series"] - 1.0) <= CHANGED]
    k = len(changed)
    names = {z["name"] for z in changed}
    by_distance = sorted(zones, key=lambda z: -z["distance"])[:k]
    by_share = sorted(zones, key=lambda z: -z["share"])
    errors = [abs(z["E"] / z["series"] - 1.0) for z in changed]
    within = sum(1 for z in changed
                 if min(z["series"], z["parallel"]) * 0.999 <= z["E"]
                 <= max(z["series"], z["parallel"]) * 1.001)
    other_errors = [z["E"] / z["series"] - 1.0 for z in others]
    return zones, {
        "changed_zones": k,
        "found_by_moduli": sum(1 for z in by_distance if z["name"] in names),
        "found_by_error_map": sum(1 for z in by_share[:k] if z["name"] in names),
        "error_map_peak_changed": by_share[0]["name"] in names,
        "changed_worst_error": max(errors),
        "changed_within_bounds": within,
        "other_worst_error": max(abs(e) for e in other_errors),
        "other_rms_error": math.sqrt(sum(e * e for e in other_errors) / len(other_errors)),
    }


def write_maps(folder, zones, title):
    """maps.png: truth (series), identified and nominal error share on the zone grid."""
    data = os.path.join(folder, "maps.dat")
    lines = ["# i j truth_series identified error_share_nominal"]
    for z in zones:
        _, i, j = z["name"].split("_")
        lines.append(f"{i} {j} {z['series']:.6f} {z['E']:.6f} {z['share']:.6g}")
    write_atomic(data, "\n".join(lines) + "\n")
    png = os.path.join(folder, "maps.png")
    script = f"""set terminal pngcairo size 900,760 font ",10"
set output "{png}.tmp"
set multiplot layout 3,1 title "{title}" noenhanced
set xrange [-0.5:{GRID[0] - 0.5}]
set yrange [-0.5:{GRID[1] - 0.5}]
set size ratio {GRID[1] / GRID[0] * LENGTH / HEIGHT / 4:.4f}
set xlabel "zone column (x, 0.025 m each)"
set ylabel "row (y)"
set cbrange [0.5:1.3]
set palette defined (0.5 "dark-red", 0.7 "red", 1.0 "white", 1.3 "blue")
set title "truth: zone modulus in series / 200 GPa"
plot "{data}" using 1:2:3 with image notitle
set title "identified by the MCRE / 200 GPa"
plot "{data}" using 1:2:4 with image notitle
set autoscale cb
set palette defined (0 "white", 1 "dark-green")
set title "error map at the nominal moduli: share of e^2 per zone"
plot "{data}" using 1:2:5 with image notitle
unset multiplot
"""
    subprocess.run(["gnuplot"], input=script, text=True, check=True)
    os.replace(png + ".tmp", png)


def case_title(truth, manifest, snr):
    return f"{truth.replace('_', ' ')}, {manifest.replace('_', ' ')}, SNR {snr:g}"


def main():
    build_dir, results = sys.argv[1], sys.argv[2]
    if sys.argv[3:] == ["--figures-only"]:
        for truth, manifest, snr in CASES:
            out = os.path.join(results, case_name(truth, manifest, snr))
            zones, _ = analyse(os.path.join(out, "zones.csv"), truth)
            write_maps(out, zones, case_title(truth, manifest, snr))
        print(f"drew {len(CASES)} maps.png in {results}")
        return
    os.makedirs(results, exist_ok=True)
    header = ("case,truth,manifest,snr,changed_zones,found_by_moduli,found_by_error_map,"
              "error_map_peak_changed,changed_worst_error,changed_within_bounds,"
              "other_worst_error,other_rms_error,zone_evaluations,wall_time_s")
    rows = [header]
    table = []
    with tempfile.TemporaryDirectory() as work:
        for n, (truth, manifest, snr) in enumerate(CASES, 1):
            name = case_name(truth, manifest, snr)
            print(f"[{n}/{len(CASES)}] {name} ...", flush=True)
            run, seconds = run_case(build_dir, work, truth, manifest, snr)
            out = os.path.join(results, name)
            os.makedirs(out, exist_ok=True)
            for kept in ("zones.csv", "error_map.csv"):
                shutil.copyfile(os.path.join(run, kept), os.path.join(out, kept + ".tmp"))
                os.replace(os.path.join(out, kept + ".tmp"), os.path.join(out, kept))
            evaluations = sum(1 for _ in open(os.path.join(run, "zone_evaluations.csv"))) - 1
            zones, m = analyse(os.path.join(out, "zones.csv"), truth)
            write_maps(out, zones, case_title(truth, manifest, snr))
            print(f"    {seconds:.0f} s: {m['found_by_moduli']} / {m['changed_zones']} changed "
                  f"zones found by the moduli, {m['found_by_error_map']} by the error map; "
                  f"changed zones within {m['changed_worst_error']:.3f} of the series truth, "
                  f"the others within {m['other_worst_error']:.4f}", flush=True)
            rows.append(",".join(str(v) for v in (
                name, truth, manifest, snr, m["changed_zones"], m["found_by_moduli"],
                m["found_by_error_map"], str(m["error_map_peak_changed"]).lower(),
                f"{m['changed_worst_error']:.6f}", m["changed_within_bounds"],
                f"{m['other_worst_error']:.6f}", f"{m['other_rms_error']:.6f}", evaluations,
                f"{seconds:.1f}")))
            table.append((name, m, evaluations, seconds))
    write_atomic(os.path.join(results, "cases.csv"), "\n".join(rows) + "\n")
    md = ["# The many-zone plate: 64 zones by the MCRE (scripts/plate_zones_study.sh)", "",
          "configs/plate_zones.yaml (48 x 12 Q4 model, 16 x 4 grid of zones, total variation "
          "weighted by the discrepancy principle or the L-curve's corner) on the 96 x 24 "
          "truths of configs/plate_zones/README.md. 'Changed' zones: those whose truth in "
          "series differs from 200 GPa. Found: of the k changed zones, how many are among "
          "the k zones farthest from the homogeneous modulus (moduli) or among the k largest "
          "shares of the error map at the nominal moduli (map). Errors against the zone's "
          "truth in series; 'within bounds': between the series and parallel bounds.", "",
          "| case | changed zones | found (moduli) | found (map) | map's peak changed | "
          "changed: worst error | within bounds | others: worst error | others: rms | "
          "zone evaluations | time [s] |",
          "|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, m, evaluations, seconds in table:
        md.append(f"| {name} | {m['changed_zones']} | {m['found_by_moduli']} | "
                  f"{m['found_by_error_map']} | {'yes' if m['error_map_peak_changed'] else 'no'} | "
                  f"{100 * m['changed_worst_error']:.1f} % | {m['changed_within_bounds']} | "
                  f"{100 * m['other_worst_error']:.2f} % | {100 * m['other_rms_error']:.2f} % | "
                  f"{evaluations} | {seconds:.0f} |")
    md += ["", "Each case's folder holds zones.csv and error_map.csv of its run and maps.png "
           "(truth, identified, error map per zone).", ""]
    write_atomic(os.path.join(results, "summary.md"), "\n".join(md))
    print(f"wrote {results}/cases.csv, summary.md and {len(CASES)} case folders")


if __name__ == "__main__":
    main()
