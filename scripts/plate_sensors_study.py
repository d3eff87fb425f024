#!/usr/bin/env python3
"""Regenerates results/plate_sensors/: where a few sensors on the many-zone plate
(configs/plate_zones.yaml, 64 zones, the soft inclusion, SNR 20) can localise it, and
why, by the Cramer-Rao standard deviations of the zone moduli (docs/matrix_models.md
section 15).

For each design of DESIGNS, `identify sensors` at SNR 20 on the nominal plate: the ten
hand-placed sensors of configs/plate_zones/model/points.yaml (five strain gauges, five
displacements: count 10 keeps them all); 20 of the 1248 full-field displacements; 10 and
20 of the candidates (configs/plate_zones/model/candidates.yaml: the full field and a
strain gauge on every horizontal element edge), each chosen by greedy D-optimal design.
The full field's own std is every candidate of the second design. Then, for each design of RUNS, `identify run configs/plate_zones.yaml` on its
sensors (data.channels from the design's channels.yaml) at SNR 20, its zones set
against the truth as scripts/plate_zones_study.py does (found by the moduli and by the
error map at the nominal moduli; the changed zones' worst error, the others' worst and
rms).

Then the update step of a localise-then-update loop: the zones the UPDATE run flags
(|ln E_z - median| > FLAG_SPREAD robust standard deviations) refitted free, every other
zone tied into one modulus (model.free_zones), no penalty; update.csv sets each against
its truth.

Writes designs.csv (per design: sensors, the largest and median Cramer-Rao std of
ln E_z, its mean over the inclusion's zones), runs.csv, summary.md, <design>/ with the
design's sensors.csv, cramer_rao.csv and channels.yaml (and a run's zones.csv,
error_map.csv and maps.png: truth, identified moduli and error map per zone), and
cramer_rao.png: each design's std per zone on the 16 x 4 grid with its chosen sensors. Prints progress; files are written atomically.

Usage: /usr/bin/python3 scripts/plate_sensors_study.py BUILD_DIR RESULTS_DIR [--designs-only]
       --designs-only: no identification run; runs.csv kept as it is.
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
from plate_zones_geometry import HEIGHT, LENGTH, MODEL_ELEMENTS  # noqa: E402
from plate_zones_study import (CHANGED, GRID, ROOT, analyse, robust_outliers,  # noqa: E402
                               truth_of_zones, update_markdown, update_table, write_atomic,
                               write_maps)

SNR = 20
TRUTH = "soft_inclusion"
DESIGNS = [  # (name, manifest, count, title)
    ("points", "points", 10, "ten hand-placed sensors (5 strain gauges)"),
    ("displacements_20", "full_field", 20, "20 displacements of the full field, D-optimal"),
    ("gauges_10", "candidates", 10, "10 of the candidates, D-optimal"),
    ("gauges_20", "candidates", 20, "20 of the candidates, D-optimal"),
]
RUNS = ["points", "gauges_20"]
UPDATE = "gauges_20"  # the run whose flagged zones are refitted (localise, then update)
FLAG_SPREAD = 3.0     # a zone is flagged when |ln E_z - median| > this x 1.4826 MAD


def identify(build_dir):
    return os.path.join(build_dir, "identify", "identify")


def common_settings(manifest):
    return ["--set", f"model.manifest=plate_zones/model/{manifest}.yaml",
            "--set", f"data.snr={SNR}"]


def design(build_dir, results, name, manifest, count):
    out = os.path.join(results, name)
    subprocess.run([identify(build_dir), "sensors", os.path.join(ROOT, "configs", "plate_zones.yaml"),
                    *common_settings(manifest), "--count", str(count), "-q", "-o", out],
                   check=True)
    return out


def channels_of(folder):
    """The channel list of a design's channels.yaml (its last line)."""
    line = open(os.path.join(folder, "channels.yaml")).read().strip().splitlines()[-1]
    return line.split("[", 1)[1].rstrip("]").replace(" ", "")


def design_row(results, name, title, count):
    rows = list(csv.DictReader(open(os.path.join(results, name, "cramer_rao.csv"))))
    truths = truth_of_zones(TRUTH)
    changed = [r for r in rows if abs(truths[r["name"]][0] - 1.0) > CHANGED]
    chosen = [float(r["std_chosen"]) for r in rows]
    return {"design": name, "title": title, "sensors": count,
            "largest_std": max(chosen), "median_std": sorted(chosen)[len(chosen) // 2],
            "inclusion_mean_std": sum(float(r["std_chosen"]) for r in changed) / len(changed),
            "std": {r["name"]: float(r["std_chosen"]) for r in rows},
            "every_candidate": {r["name"]: float(r["std_every_candidate"]) for r in rows}}


def flagged_zones(zones_csv):
    """The zones a first identification flags: |ln E_z - median| above FLAG_SPREAD robust
    standard deviations (1.4826 MAD) of ln E over the zones."""
    rows = list(csv.DictReader(open(zones_csv)))
    logs = [math.log(float(r["modulus_pa"])) for r in rows]
    return [rows[i]["name"] for i in robust_outliers(logs, FLAG_SPREAD, two_sided=True)]


def run(build_dir, results, work, name, manifest, free_zones=None):
    """identify run on design `name`'s sensors; with free_zones, the update step: those
    zones free, the others tied into 'rest', no penalty, into <name>_update/."""
    folder = os.path.join(work, name + ("_update" if free_zones else ""))
    update = (["--set", f"model.free_zones=[{','.join(free_zones)}]",
               "--set", "zone_identification.regularization=none"] if free_zones else [])
    command = [identify(build_dir), "run", os.path.join(ROOT, "configs", "plate_zones.yaml"),
               *common_settings(manifest), *update, "--set",
               f"data.channels=[{channels_of(os.path.join(results, name))}]",
               # The trace preconditioner (configs/plate_zones_gauges.yaml): a few sensors'
               # strain rows make the unpreconditioned CG take hundreds of iterations.
               "--set", "inner.preconditioner=dense_traces",
               "--set", "inner.max_preconditioner_traces=4096",
               "--set", "output.curve_points=5", "--set", "output.figures=false", "-q",
               "-o", folder]
    start = time.monotonic()
    subprocess.run(command, check=True)
    seconds = time.monotonic() - start
    out = os.path.join(results, os.path.basename(folder))
    os.makedirs(out, exist_ok=True)
    for file in ("zones.csv", "error_map.csv"):
        shutil.copyfile(os.path.join(folder, file), os.path.join(out, file + ".tmp"))
        os.replace(os.path.join(out, file + ".tmp"), os.path.join(out, file))
    evaluations = sum(1 for _ in open(os.path.join(folder, "zone_evaluations.csv"))) - 1
    return seconds, evaluations


def write_update(results, seconds, evaluations):
    """update.csv: the update run's zones against their truth (update_table)."""
    write_atomic(os.path.join(results, "update.csv"),
                 update_table(os.path.join(results, UPDATE + "_update", "zones.csv"), TRUTH,
                              evaluations, seconds))


RUN_HEADER = ["design", "sensors", "changed_zones", "found_by_moduli", "found_by_error_map",
              "error_map_peak_changed", "changed_worst_error", "other_worst_error",
              "other_rms_error", "zone_evaluations", "wall_time_s"]


def sensor_nodes(results, name):
    """(x, y) [m] of the candidates a design chose: the node of u<axis>_<i>_<j>, the
    middle of gauge exx_<i>_<j>'s edge."""
    nx, ny = MODEL_ELEMENTS
    nodes = []
    for channel in channels_of(os.path.join(results, name)).split(","):
        parts = channel.split("_")
        if len(parts) == 3 and parts[0] in ("ux", "uy", "exx") and parts[1].isdigit():
            i = int(parts[1]) + (0.5 if parts[0] == "exx" else 0.0)
            nodes.append((i * LENGTH / nx, int(parts[2]) * HEIGHT / ny, parts[0]))
    return nodes


def write_figure(results, designs):
    full_field = next(d for d in designs if d["design"] == "displacements_20")
    panels = designs + [{"design": "full_field", "title": "the full field (1248 channels)",
                         "std": full_field["every_candidate"]}]
    data = os.path.join(results, "cramer_rao.dat")
    lines = ["# i j " + " ".join(p["design"] for p in panels)]
    for name in sorted(panels[0]["std"], key=lambda n: tuple(int(v) for v in n.split("_")[1:])):
        _, i, j = name.split("_")
        lines.append(f"{i} {j} " + " ".join(f"{100 * p['std'][name]:.4f}" for p in panels))
    write_atomic(data, "\n".join(lines) + "\n")
    plots = []
    for k, p in enumerate(panels):
        nodes = sensor_nodes(results, p["design"]) if p["design"] != "full_field" else []
        node_file = os.path.join(results, f"{p['design']}_nodes.dat")
        if nodes:
            # Nodes in zone-grid coordinates: x / (L / 16) - 0.5, y / (H / 4) - 0.5.
            write_atomic(node_file, "".join(
                f"{x / (LENGTH / GRID[0]) - 0.5:.4f} {y / (HEIGHT / GRID[1]) - 0.5:.4f}\n"
                for x, y, _ in nodes))
        overlay = (f', "{node_file}" using 1:2 with points pt 7 ps 1.2 lc rgb "black" '
                   'notitle') if nodes else ""
        where = ", black: sensors" if nodes else ""
        plots.append(f'set title "{p["title"]}{where}: Cramer-Rao std of ln E_z [%] at SNR '
                     f'{SNR}" noenhanced\n'
                     f'plot "{data}" using 1:2:{k + 3} with image notitle{overlay}\n')
    png = os.path.join(results, "cramer_rao.png")
    script = f"""set terminal pngcairo size 900,{250 * len(panels) + 10} font ",10"
set output "{png}.tmp"
set multiplot layout {len(panels)},1
set xrange [-0.5:{GRID[0] - 0.5}]
set yrange [-0.5:{GRID[1] - 0.5}]
set size ratio {GRID[1] / GRID[0] * LENGTH / HEIGHT / 4:.4f}
set xlabel "zone column (x, 0.025 m each; the load at the right end)"
set ylabel "row (y)"
set logscale cb
set cbrange [0.2:20]
set palette defined (0 "white", 0.5 "orange", 1 "dark-red")
{"".join(plots)}unset multiplot
"""
    subprocess.run(["gnuplot"], input=script, text=True, check=True)
    os.replace(png + ".tmp", png)


def write_summary(results, designs, runs):
    md = ["# Few sensors on the many-zone plate (scripts/plate_sensors_study.sh)", "",
          f"configs/plate_zones.yaml (64 zones), the soft inclusion, SNR {SNR}. Designs by "
          "`identify sensors` (greedy D-optimal on the zone moduli's Fisher information at "
          "the nominal moduli, docs/matrix_models.md section 15); the Cramer-Rao standard "
          "deviation of ln E_z is the relative error of E_z an unbiased, unregularised fit "
          "cannot beat under the noise alone.", "",
          "| design | sensors | largest std | median std | inclusion zones: mean std |",
          "|---|---|---|---|---|"]
    for d in designs:
        md.append(f"| {d['title']} | {d['sensors']} | {100 * d['largest_std']:.2f} % | "
                  f"{100 * d['median_std']:.2f} % | {100 * d['inclusion_mean_std']:.2f} % |")
    full = list(next(d for d in designs if d["design"] == "displacements_20")
                ["every_candidate"].values())
    md.append(f"| the full field | 1248 | {100 * max(full):.2f} % | "
              f"{100 * sorted(full)[len(full) // 2]:.2f} % | - |")
    md += ["", "Identification (MCRE, total variation, the weight rule of "
           "configs/plate_zones.yaml) on each design's sensors; found: of the k changed "
           "zones, how many among the k farthest from the mean (moduli) or the k largest "
           "shares of the error map at the nominal moduli (map).", "",
           "| design | found (moduli) | found (map) | map's peak changed | changed: worst | "
           "others: worst, rms | zone evaluations | time [s] |",
           "|---|---|---|---|---|---|---|---|"]
    for r in runs:
        md.append(f"| {r['design']} | {r['found_by_moduli']} of {r['changed_zones']} | "
                  f"{r['found_by_error_map']} | {r['error_map_peak_changed']} | "
                  f"{100 * float(r['changed_worst_error']):.1f} % | "
                  f"{100 * float(r['other_worst_error']):.1f} %, "
                  f"{100 * float(r['other_rms_error']):.1f} % | {r['zone_evaluations']} | "
                  f"{float(r['wall_time_s']):.0f} |")
    update_path = os.path.join(results, "update.csv")
    if os.path.exists(update_path):
        rows = list(csv.DictReader(open(update_path)))
        md += ["", f"Localise, then update: the zones the {UPDATE} run flags (|ln E_z - median| "
               f"> {FLAG_SPREAD:g} x 1.4826 MAD) refitted free, every other zone tied into one "
               "modulus 'rest', no penalty (model.free_zones; "
               f"{rows[0]['zone_evaluations']} evaluations, {float(rows[0]['wall_time_s']):.0f} s).",
               ""] + update_markdown(update_path)
    md += ["", "cramer_rao.png: each design's std per zone, the chosen sensors in black "
           "(a gauge at its edge's middle). Each design's folder: sensors.csv, cramer_rao.csv, channels.yaml; "
           "with a run, its zones.csv, error_map.csv and maps.png (truth, moduli, error "
           "map).", ""]
    write_atomic(os.path.join(results, "summary.md"), "\n".join(md))


def main():
    build_dir, results = sys.argv[1], sys.argv[2]
    options = sys.argv[3:]
    if options not in ([], ["--designs-only"]):
        sys.exit(f"unknown options {options}: expected [--designs-only]")
    os.makedirs(results, exist_ok=True)
    designs = []
    for n, (name, manifest, count, title) in enumerate(DESIGNS, 1):
        print(f"[design {n}/{len(DESIGNS)}] {name} ...", flush=True)
        design(build_dir, results, name, manifest, count)
        designs.append(design_row(results, name, title, count))
    write_atomic(os.path.join(results, "designs.csv"),
                 "design,sensors,largest_std,median_std,inclusion_mean_std\n" + "".join(
                     f"{d['design']},{d['sensors']},{d['largest_std']:.6f},"
                     f"{d['median_std']:.6f},{d['inclusion_mean_std']:.6f}\n" for d in designs))
    runs_path = os.path.join(results, "runs.csv")
    if options == ["--designs-only"]:
        runs = list(csv.DictReader(open(runs_path))) if os.path.exists(runs_path) else []
        update_path = os.path.join(results, "update.csv")
        if os.path.exists(update_path):
            kept = next(csv.DictReader(open(update_path)))
            write_update(results, float(kept["wall_time_s"]), kept["zone_evaluations"])
    else:
        runs = []
        manifests = {name: manifest for name, manifest, _, _ in DESIGNS}
        with tempfile.TemporaryDirectory() as work:
            for n, name in enumerate(RUNS, 1):
                print(f"[run {n}/{len(RUNS)}] {name} ...", flush=True)
                seconds, evaluations = run(build_dir, results, work, name, manifests[name])
                _, m = analyse(os.path.join(results, name, "zones.csv"), TRUTH)
                print(f"    {seconds:.0f} s: {m['found_by_moduli']} / {m['changed_zones']} "
                      f"found by the moduli, {m['found_by_error_map']} by the map", flush=True)
                runs.append({"design": name,
                             "sensors": next(d["sensors"] for d in designs if d["design"] == name),
                             **{k: m[k] for k in RUN_HEADER[2:9]},
                             "zone_evaluations": evaluations, "wall_time_s": f"{seconds:.1f}"})
            # Localise, then update: the zones the run flags free, the others tied.
            flagged = flagged_zones(os.path.join(results, UPDATE, "zones.csv"))
            print(f"[update] {UPDATE}: {len(flagged)} zones flagged ({', '.join(flagged)}), "
                  "refitted free against one background modulus ...", flush=True)
            seconds, evaluations = run(build_dir, results, work, UPDATE, manifests[UPDATE],
                                       flagged)
            write_update(results, seconds, evaluations)
        write_atomic(runs_path, ",".join(RUN_HEADER) + "\n" + "".join(
            ",".join(str(r[h]) for h in RUN_HEADER) + "\n" for r in runs))
    write_figure(results, designs)
    titles = {name: title for name, _, _, title in DESIGNS}
    for r in runs:
        zones, _ = analyse(os.path.join(results, r["design"], "zones.csv"), TRUTH)
        write_maps(os.path.join(results, r["design"]), zones, None,
                   f"soft inclusion, {titles[r['design']]}, SNR {SNR}")
    write_summary(results, designs, runs)
    print(f"wrote {results}/designs.csv, runs.csv, summary.md and cramer_rao.png")


if __name__ == "__main__":
    main()
