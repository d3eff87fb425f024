#!/usr/bin/env python3
"""Regenerates results/plate_zones/: the 64 zones of the many-zone plate
(configs/plate_zones.yaml, configs/plate_zones/README.md) identified by the MCRE and by
output-error least squares (the same zones, data, total variation and weight rule) for
each case of CASES (truth, sensor set, SNR), and each run's zones set against its truth.

For every case and functional, `identify run configs/plate_zones.yaml` with the case's
truth, manifest and SNR (the cost curve at 5 points, no figures of its own) into a
temporary folder; its zones.csv (least squares: least_squares_zones.csv) and, by the
MCRE, error_map.csv are kept in results/plate_zones/<case>/. Then, per run:

  - the truth of each zone: the moduli of the truth's fine elements whose model element
    lies in the zone, combined in series (1 / E = mean of 1 / E_el, the Reuss bound) and
    in parallel (mean of E_el, the Voigt bound); a zone is 'changed' when its series
    modulus differs from 200 GPa by more than 0.1 %;
  - localisation: of the k changed zones, how many are among the k zones farthest from
    the zones' geometric mean (|ln E_z / E_mean|), and, by the MCRE, how many among the k
    largest shares of the error map at the nominal moduli (zones.csv
    error_share_nominal) and among the k largest gaps relative to the zone's strain
    energy (relative_gap_nominal: the normalised map); whether the map's peak is a
    changed zone;
  - sizing: the changed zones' worst relative error against the series truth (and
    how many lie between the two bounds), the other zones' worst and rms error.

Writes cases.csv (a row per case and functional), summary.md (from cases.csv), and
<case>/maps.png: the truth (series), the MCRE's and least squares' moduli, and the error
map's share per zone at the nominal moduli, on the 16 x 4 grid (gnuplot). Prints
progress; the files are written atomically.

Usage: /usr/bin/python3 scripts/plate_zones_study.py BUILD_DIR RESULTS_DIR
           [--functional mcre|least_squares|both | --figures-only | --update-only |
            --element-update-only | --per-element-only [--functional F]]
       --functional: the runs to make (default both); the other functional's rows of an
           existing cases.csv are kept.
       --figures-only: no run; cases.csv's measures computed again from the kept files
           (times and evaluations kept), maps.png and summary.md drawn again.
       --update-only: the update step alone (below), from the kept zones.csv of its case.
       --element-update-only: the per-element update step alone (below).

After the MCRE's runs, the update step of a localise-then-update loop on UPDATE_CASE: the
zones its error map at the nominal moduli flags (a share above the median by more than 3
robust standard deviations) free, the others tied into one modulus, no penalty
(model.free_zones); update.csv sets each against its truth. Then the per-element update
step on each of ELEMENT_UPDATE_CASES: every model element of the zones its map flags free
(model.zoning: per_element), the others tied, total variation between elements that share
a node with its weight from the misfit floor held to the noise the free elements fit
(zone_identification.neighbours: shared_nodes, floor_margin: noise_fit);
element_update.csv sets each flagged zone, its modulus the series combination of its
elements' moduli, against its truth, and <case>/element_update.png draws the elements'
truth and moduli. Last, every element of the plate free with the same penalty and rule
on PER_ELEMENT_CASE, by each functional run (least squares with its gradient by the
discrete adjoint): per_element.csv and <case>/per_element.png of the MCRE,
per_element_least_squares.csv and <case>/per_element_least_squares.png of least squares.
       --per-element-only [--functional mcre|least_squares|both]: those last runs alone.
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
# The case whose error map at the nominal moduli chooses the zones of the update step:
# those it flags free, the others tied into one modulus, no penalty (model.free_zones).
UPDATE_CASE = ("soft_inclusion", "full_field", 10)


def case_name(truth, manifest, snr):
    return f"{truth}_{manifest}_snr{snr:g}"


def write_atomic(path, text):
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def copy_atomic(source, target):
    """Copies `source` to `target` through a temporary file beside it."""
    shutil.copyfile(source, target + ".tmp")
    os.replace(target + ".tmp", target)


def zone_evaluations(run):
    """The zone evaluations of an identify run's folder (zone_evaluations.csv's rows)."""
    return sum(1 for _ in open(os.path.join(run, "zone_evaluations.csv"))) - 1


def relative_moduli(zones_csv):
    """Per zone name of a zones.csv, its modulus / NOMINAL_MODULUS."""
    return {r["name"]: float(r["modulus_pa"]) / NOMINAL_MODULUS
            for r in csv.DictReader(open(zones_csv))}


def element_positions():
    """Per element of the model's manifest, in its order: its (i, j) on the
    MODEL_ELEMENTS grid, from configs/plate_zones/model/element_positions.csv."""
    nx, ny = MODEL_ELEMENTS
    cells = []
    path = os.path.join(ROOT, "configs", "plate_zones", "model", "element_positions.csv")
    for line in open(path):
        if line.startswith("#") or not line.strip():
            continue
        x, y = (float(v) for v in line.split(","))
        cells.append((round(x / (LENGTH / nx) - 0.5), round(y / (HEIGHT / ny) - 0.5)))
    return cells


def zone_of_element(i, j):
    """The grid zone of model element (i, j) (RegroupedElementZones: boxes over the
    centroids' extent)."""
    nx, ny = MODEL_ELEMENTS
    return (f"grid_{min(GRID[0] - 1, int(i / (nx - 1) * GRID[0]))}_"
            f"{min(GRID[1] - 1, int(j / (ny - 1) * GRID[1]))}")


def fine_moduli(truth, i, j):
    """The relative moduli of the truth's fine elements under model element (i, j)."""
    nx, ny = MODEL_ELEMENTS
    fine_dx, fine_dy = LENGTH / (nx * REFINE), HEIGHT / (ny * REFINE)
    values = []
    for a in range(REFINE):
        for b in range(REFINE):
            x = (i * REFINE + a + 0.5) * fine_dx
            y = (j * REFINE + b + 0.5) * fine_dy
            value = 1.0
            for _, modulus, inside in TRUTHS[truth]:
                if inside(x, y):
                    value = modulus
            values.append(value)
    return values


def series(values):
    return len(values) / sum(1.0 / v for v in values)


def truth_of_zones(truth):
    """Per zone name grid_i_j: (series, parallel) moduli relative to NOMINAL_MODULUS of
    the truth's fine elements under the zone's model elements."""
    nx, ny = MODEL_ELEMENTS
    moduli = {}
    for j in range(ny):
        for i in range(nx):
            moduli.setdefault(zone_of_element(i, j), []).extend(fine_moduli(truth, i, j))
    return {name: (series(m), sum(m) / len(m)) for name, m in moduli.items()}


FUNCTIONALS = ("mcre", "least_squares")


def zones_file(functional):
    return "zones.csv" if functional == "mcre" else "least_squares_zones.csv"


def median_of(values):
    ordered = sorted(values)
    n = len(ordered)
    return ordered[n // 2] if n % 2 else 0.5 * (ordered[n // 2 - 1] + ordered[n // 2])


def robust_outliers(values, spread, two_sided=False):
    """Indices of the values above their median (or on either side, two_sided) by more
    than `spread` robust standard deviations (1.4826 MAD)."""
    median = median_of(values)
    mad = median_of([abs(v - median) for v in values])
    return [i for i, v in enumerate(values)
            if (abs(v - median) if two_sided else v - median) > spread * 1.4826 * mad]


def map_flagged(zones_csv, spread=3.0):
    """The zones the error map at the nominal moduli flags: a share of the gap above its
    median over the zones by more than `spread` robust standard deviations."""
    rows = list(csv.DictReader(open(zones_csv)))
    shares = [float(r["error_share_nominal"]) for r in rows]
    return [rows[i]["name"] for i in robust_outliers(shares, spread)]


def rest_truth(truths, free):
    """The truth of 'rest', the union of the zones of `truths` not in `free`, each of the
    same number of fine elements: (series, parallel), the harmonic mean of their series
    truths and the mean of their parallel ones."""
    tied = [truths[name] for name in truths if name not in free]
    return (len(tied) / sum(1.0 / t[0] for t in tied), sum(t[1] for t in tied) / len(tied))


def update_table(zones_csv, truth, evaluations, seconds):
    """update.csv's text: each zone of an update run (rest, then the free ones) against
    its truth in series and in parallel. 'rest' is the union of the other zones, each of
    the same number of fine elements: its series truth the harmonic mean of theirs, its
    parallel truth the mean."""
    truths = truth_of_zones(truth)
    rows = list(csv.DictReader(open(zones_csv)))
    truths["rest"] = rest_truth(truths, {r["name"] for r in rows})
    lines = ["zone,modulus_relative,truth_series,truth_parallel,error_series,"
             "zone_evaluations,wall_time_s"]
    for r in rows:
        series, parallel = truths[r["name"]]
        modulus = float(r["modulus_pa"]) / NOMINAL_MODULUS
        lines.append(f"{r['name']},{modulus:.6f},{series:.6f},{parallel:.6f},"
                     f"{modulus / series - 1.0:.6f},{evaluations},{seconds:.1f}")
    return "\n".join(lines) + "\n"


def update_markdown(update_csv):
    """The table of an update.csv in markdown."""
    md = ["| zone | identified / 200 GPa | truth in series | in parallel | error (series) |",
          "|---|---|---|---|---|"]
    for r in csv.DictReader(open(update_csv)):
        md.append(f"| {r['zone']} | {float(r['modulus_relative']):.3f} | "
                  f"{float(r['truth_series']):.3f} | {float(r['truth_parallel']):.3f} | "
                  f"{100 * float(r['error_series']):+.1f} % |")
    return md


def run_case(build_dir, work, truth, manifest, snr, functional, free_zones=None, settings=(),
             suffix=""):
    """identify run on a case; with free_zones the update step (those zones free, the
    others tied into 'rest', no penalty); settings: further --set KEY=VALUE."""
    moduli = [1.0] + [modulus for _, modulus, _ in TRUTHS[truth]]
    folder = os.path.join(work, case_name(truth, manifest, snr) + "_" + functional +
                          ("_update" if free_zones else "") + suffix)
    command = [os.path.join(build_dir, "identify", "identify"), "run",
               os.path.join(ROOT, "configs", "plate_zones.yaml"),
               "--set", f"model.manifest=plate_zones/model/{manifest}.yaml",
               "--set", f"data.truth_manifest=plate_zones/truth/{truth}.yaml",
               "--set", "data.truth_moduli=[" +
               ",".join(f"{m * NOMINAL_MODULUS:.17g}" for m in moduli) + "]",
               "--set", f"data.snr={snr:g}", "--set", "output.curve_points=5",
               "--set", "output.figures=false", "-q", "-o", folder]
    if functional == "least_squares":
        command[3:3] = ["--set", "outer.functional=least_squares"]
    if free_zones:
        command[3:3] = ["--set", f"model.free_zones=[{','.join(free_zones)}]",
                        "--set", "zone_identification.regularization=none"]
    for setting in settings:
        command[3:3] = ["--set", setting]
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
                      "share": float(r["error_share_nominal"] or "nan"),
                      "relative_gap": float(r["relative_gap_nominal"] or "nan"),
                      "distance": abs(math.log(float(r["modulus_pa"]) / homogeneous))})
    changed = [z for z in zones if abs(z["series"] - 1.0) > CHANGED]
    others = [z for z in zones if abs(z["series"] - 1.0) <= CHANGED]
    k = len(changed)
    names = {z["name"] for z in changed}
    by_distance = sorted(zones, key=lambda z: -z["distance"])[:k]
    mapped = not math.isnan(zones[0]["share"])  # least squares has no error map
    by_share = sorted(zones, key=lambda z: -z["share"]) if mapped else []
    errors = [abs(z["E"] / z["series"] - 1.0) for z in changed]
    within = sum(1 for z in changed
                 if min(z["series"], z["parallel"]) * 0.999 <= z["E"]
                 <= max(z["series"], z["parallel"]) * 1.001)
    other_errors = [z["E"] / z["series"] - 1.0 for z in others]
    return zones, {
        "changed_zones": k,
        "found_by_moduli": sum(1 for z in by_distance if z["name"] in names),
        "found_by_error_map": sum(1 for z in by_share[:k] if z["name"] in names) if mapped else "",
        # The normalised map: the zone's gap over its strain energy (zones.csv
        # relative_gap_nominal), the same order as share over share of the energy.
        "found_by_relative_gap": (sum(1 for z in sorted(zones, key=lambda z: -z["relative_gap"])[:k]
                                      if z["name"] in names) if mapped else ""),
        "error_map_peak_changed": (str(by_share[0]["name"] in names).lower() if mapped else ""),
        "changed_worst_error": max(errors),
        "changed_within_bounds": within,
        "other_worst_error": max(abs(e) for e in other_errors),
        "other_rms_error": math.sqrt(sum(e * e for e in other_errors) / len(other_errors)),
    }


def map_preamble(png, height, panels, title, cells, ratio, xlabel):
    """The gnuplot lines a figure of moduli on a grid of cells = (columns, rows) starts
    with: `panels` panels one above the other, the moduli's colour scale."""
    return f"""set terminal pngcairo size 900,{height} font ",10"
set output "{png}.tmp"
set multiplot layout {panels},1 title "{title}" noenhanced
set xrange [-0.5:{cells[0] - 0.5}]
set yrange [-0.5:{cells[1] - 0.5}]
set size ratio {ratio:.4f}
set xlabel "{xlabel}"
set ylabel "row (y)"
set cbrange [0.5:1.3]
set palette defined (0.5 "dark-red", 0.7 "red", 1.0 "white", 1.3 "blue")
"""


def write_maps(folder, zones, ls_zones, title):
    """maps.png: truth (series), the MCRE's and least squares' moduli (ls_zones: None when
    not run) and the nominal error share on the zone grid."""
    data = os.path.join(folder, "maps.dat")
    ls = {z["name"]: z["E"] for z in ls_zones} if ls_zones else {}
    lines = ["# i j truth_series mcre error_share_nominal least_squares"]
    for z in zones:
        _, i, j = z["name"].split("_")
        lines.append(f"{i} {j} {z['series']:.6f} {z['E']:.6f} {z['share']:.6g} "
                     f"{ls.get(z['name'], float('nan')):.6f}")
    write_atomic(data, "\n".join(lines) + "\n")
    png = os.path.join(folder, "maps.png")
    panels = 4 if ls else 3
    ls_panel = (f"""set title "identified by least squares / 200 GPa"
plot "{data}" using 1:2:6 with image notitle
""" if ls else "")
    script = map_preamble(png, 250 * panels + 10, panels, title, GRID,
                          GRID[1] / GRID[0] * LENGTH / HEIGHT / 4,
                          "zone column (x, 0.025 m each)") + f"""set title "truth: zone modulus in series / 200 GPa"
plot "{data}" using 1:2:3 with image notitle
set title "identified by the MCRE / 200 GPa"
plot "{data}" using 1:2:4 with image notitle
{ls_panel}set autoscale cb
set palette defined (0 "white", 1 "dark-green")
set title "error map at the nominal moduli: share of e^2 per zone"
plot "{data}" using 1:2:5 with image notitle
unset multiplot
"""
    subprocess.run(["gnuplot"], input=script, text=True, check=True)
    os.replace(png + ".tmp", png)


def case_title(truth, manifest, snr):
    return f"{truth.replace('_', ' ')}, {manifest.replace('_', ' ')}, SNR {snr:g}"


HEADER = ["case", "functional", "truth", "manifest", "snr", "changed_zones", "found_by_moduli",
          "found_by_error_map", "found_by_relative_gap", "error_map_peak_changed",
          "changed_worst_error",
          "changed_within_bounds", "other_worst_error", "other_rms_error", "zone_evaluations",
          "wall_time_s"]


def case_row(name, functional, truth, manifest, snr, m, evaluations, seconds):
    return {"case": name, "functional": functional, "truth": truth, "manifest": manifest,
            "snr": f"{snr:g}", "changed_zones": m["changed_zones"],
            "found_by_moduli": m["found_by_moduli"],
            "found_by_error_map": m["found_by_error_map"],
            "found_by_relative_gap": m["found_by_relative_gap"],
            "error_map_peak_changed": m["error_map_peak_changed"],
            "changed_worst_error": f"{m['changed_worst_error']:.6f}",
            "changed_within_bounds": m["changed_within_bounds"],
            "other_worst_error": f"{m['other_worst_error']:.6f}",
            "other_rms_error": f"{m['other_rms_error']:.6f}", "zone_evaluations": evaluations,
            "wall_time_s": f"{seconds:.1f}"}


def read_cases(results):
    """The rows of results/cases.csv; none when it does not exist. A file written before
    least squares joined the study holds the MCRE's rows only, without the column."""
    path = os.path.join(results, "cases.csv")
    if not os.path.exists(path):
        return []
    rows = list(csv.DictReader(open(path)))
    for row in rows:
        row.setdefault("functional", "mcre")
    return rows


def write_cases(results, rows):
    order = {case_name(*c): i for i, c in enumerate(CASES)}
    rows = sorted(rows, key=lambda r: (order[r["case"]], FUNCTIONALS.index(r["functional"])))
    text = ",".join(HEADER) + "\n" + "".join(
        ",".join(str(r[h]) for h in HEADER) + "\n" for r in rows)
    write_atomic(os.path.join(results, "cases.csv"), text)


def write_summary(results):
    rows = read_cases(results)
    md = ["# The many-zone plate: 64 zones by the MCRE and by least squares "
          "(scripts/plate_zones_study.sh)", "",
          "configs/plate_zones.yaml (48 x 12 Q4 model, 16 x 4 grid of zones, total variation "
          "weighted by the discrepancy principle or the L-curve's corner) on the 96 x 24 "
          "truths of configs/plate_zones/README.md; least squares on the same zones and data "
          "with the same penalty and weight rule (outer.functional: least_squares). 'Changed' "
          "zones: those whose truth in series differs from 200 GPa. Found: of the k changed "
          "zones, how many are among the k zones farthest from the zones' geometric mean "
          "(moduli), among the k largest shares of the MCRE's error map at the nominal "
          "moduli (map), or among the k largest gaps relative to the zone's strain energy "
          "there (gap / energy: the normalised map). Errors against the zone's truth in "
          "series; 'within bounds': between the series and parallel bounds.", "",
          "| case | functional | changed zones | found (moduli) | found (map) | found (gap / "
          "energy) | map's peak changed | changed: worst error | within bounds | others: worst "
          "error | others: rms | zone evaluations | time [s] |",
          "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        peak = {"true": "yes", "false": "no"}.get(r["error_map_peak_changed"], "-")
        md.append(f"| {r['case']} | {r['functional'].replace('_', ' ')} | {r['changed_zones']} | "
                  f"{r['found_by_moduli']} | {r['found_by_error_map'] or '-'} | "
                  f"{r['found_by_relative_gap'] or '-'} | {peak} | "
                  f"{100 * float(r['changed_worst_error']):.1f} % | {r['changed_within_bounds']} | "
                  f"{100 * float(r['other_worst_error']):.2f} % | "
                  f"{100 * float(r['other_rms_error']):.2f} % | {r['zone_evaluations']} | "
                  f"{float(r['wall_time_s']):.0f} |")
    update_path = os.path.join(results, "update.csv")
    if os.path.exists(update_path):
        first = next(csv.DictReader(open(update_path)))
        md += ["", f"Localise, then update ({case_name(*UPDATE_CASE)}, MCRE): the zones whose "
               "share of the error map at the nominal moduli lies above the median by more than "
               "3 x 1.4826 MAD refitted free, every other zone tied into one modulus 'rest', no "
               f"penalty (model.free_zones; {first['zone_evaluations']} zone evaluations, "
               f"{float(first['wall_time_s']):.0f} s; update.csv, the case's update_zones.csv).",
               ""] + update_markdown(update_path)
    element_path = os.path.join(results, "element_update.csv")
    if os.path.exists(element_path):
        md += ["", "Localise, then update per element: on each case, every model element of the "
               "zones its error map flags (as above) free, the others tied into 'rest', total "
               "variation between elements that share a node, its weight from the misfit floor "
               "held to the noise the free elements fit (zone_identification.floor_margin: "
               "noise_fit; element_update.csv, the case's element_update_zones.csv and "
               "element_update.png). A flagged zone's modulus is the series combination of its "
               "elements' moduli."] + element_markdown(element_path)
    per_element_texts = [
        ("mcre", "The whole plate per element (576 moduli from the homogeneous E*, no "
         "localisation; the same penalty and weight rule; per_element.csv, the case's "
         "per_element_zones.csv and per_element.png), each zone's modulus the series "
         "combination of its nine elements'. Changed zones and the others:"),
        ("least_squares", "The same by least squares (outer.functional: least_squares, its "
         "gradient by the discrete adjoint, zone_identification.least_squares_gradient: "
         "adjoint; per_element_least_squares.csv, the case's "
         "per_element_least_squares_zones.csv and per_element_least_squares.png):")]
    for functional, text in per_element_texts:
        path = os.path.join(results, per_element_stem(functional) + ".csv")
        if os.path.exists(path):
            md += ["", text] + element_markdown(path, changed_only=True)
    md += ["", "Each case's folder holds zones.csv and error_map.csv of the MCRE's run, "
           "least_squares_zones.csv of least squares', and maps.png (truth, both functionals' "
           "moduli, error map per zone).", ""]
    write_atomic(os.path.join(results, "summary.md"), "\n".join(md))


def element_markdown(path, changed_only=False):
    """The tables of element_update.csv or per_element.csv, one per case; changed_only:
    the changed zones' rows and one row for the others' worst and rms error."""
    by_case = {}
    for r in csv.DictReader(open(path)):
        by_case.setdefault(r["case"], []).append(r)
    md = []
    for case, rows in by_case.items():
        md += ["", f"{case}: {rows[0]['zone_evaluations']} zone evaluations, "
               f"{float(rows[0]['wall_time_s']):.0f} s.", "",
               "| zone | identified / 200 GPa | truth in series | in parallel | error (series) |",
               "|---|---|---|---|---|"]
        others = []
        for r in rows:
            if changed_only and abs(float(r["truth_series"]) - 1.0) <= CHANGED:
                others.append(float(r["error_series"]))
                continue
            md.append(f"| {r['zone']} | {float(r['modulus_relative']):.3f} | "
                      f"{float(r['truth_series']):.3f} | {float(r['truth_parallel']):.3f} | "
                      f"{100 * float(r['error_series']):+.1f} % |")
        if others:
            rms = math.sqrt(sum(e * e for e in others) / len(others))
            md.append(f"| the {len(others)} others | worst {100 * max(map(abs, others)):.2f} %, "
                      f"rms {100 * rms:.2f} % | 1 | 1 | |")
    return md


def run_update(build_dir, results):
    """The update step on UPDATE_CASE from its kept zones.csv: its map's flagged zones
    free, the rest tied; <case>/update_zones.csv and update.csv."""
    truth, manifest, snr = UPDATE_CASE
    out = os.path.join(results, case_name(*UPDATE_CASE))
    flagged = map_flagged(os.path.join(out, "zones.csv"))
    print(f"[update] {case_name(*UPDATE_CASE)}: the error map flags {len(flagged)} zones "
          f"({', '.join(flagged)}); refitted free against one background modulus ...", flush=True)
    with tempfile.TemporaryDirectory() as work:
        run, seconds = run_case(build_dir, work, truth, manifest, snr, "mcre", flagged)
        copy_atomic(os.path.join(run, "zones.csv"), os.path.join(out, "update_zones.csv"))
        evaluations = zone_evaluations(run)
    write_atomic(os.path.join(results, "update.csv"),
                 update_table(os.path.join(out, "update_zones.csv"), truth, evaluations, seconds))
    print(f"    {seconds:.0f} s", flush=True)


# The per-element update's settings: every element of the flagged zones free, total
# variation between elements that share a node, the weight by the misfit floor held to
# the noise the free elements fit, no uncertainty estimate (2 x 82 solves).
ELEMENT_UPDATE_SETTINGS = ["model.zoning=per_element", "model.zone_grid=[]",
                           "zone_identification.regularization=total_variation",
                           "zone_identification.neighbours=shared_nodes",
                           "zone_identification.floor_margin=noise_fit",
                           "zone_identification.max_time=3600", "uncertainty.samples=0"]


# The cases of the per-element update (their MCRE runs' zones.csv flag the zones), and
# the case of the whole plate per element.
ELEMENT_UPDATE_CASES = [("soft_inclusion", "full_field", 10), ("soft_inclusion", "full_field", 5)]
PER_ELEMENT_CASE = ("soft_inclusion", "full_field", 10)
ELEMENT_HEADER = ("case,zone,modulus_relative,truth_series,truth_parallel,error_series,"
                  "zone_evaluations,wall_time_s")


def element_table_rows(name, zones_csv, truth, evaluations, seconds):
    """The rows of element_update.csv or per_element.csv for one run of case `name`:
    each zone with an element free, its modulus the series combination of its elements'
    identified moduli (each element holds the same number of fine elements, so the
    series of series is the zone's series), against its truth; 'rest' (when the run has
    it) as in update_table."""
    identified = relative_moduli(zones_csv)
    truths = truth_of_zones(truth)
    by_zone = {}
    for e, (i, j) in enumerate(element_positions()):
        if f"element{e}" in identified:
            by_zone.setdefault(zone_of_element(i, j), []).append(identified[f"element{e}"])
    moduli = [(zone, series(m)) for zone, m in sorted(by_zone.items())]
    if "rest" in identified:
        truths["rest"] = rest_truth(truths, by_zone)
        moduli.insert(0, ("rest", identified["rest"]))
    return [f"{name},{zone},{modulus:.6f},{truths[zone][0]:.6f},{truths[zone][1]:.6f},"
            f"{modulus / truths[zone][0] - 1.0:.6f},{evaluations},{seconds:.1f}"
            for zone, modulus in moduli]


def write_element_maps(folder, zones_csv, truth, title, stem, panel):
    """<stem>.png: the truth of each model element (its fine elements in series) and the
    run's element moduli (the tied elements at 'rest')."""
    identified = relative_moduli(zones_csv)
    data = os.path.join(folder, stem + ".dat")
    lines = ["# i j truth_series identified"]
    for e, (i, j) in enumerate(element_positions()):
        modulus = identified.get(f"element{e}", identified.get("rest"))
        lines.append(f"{i} {j} {series(fine_moduli(truth, i, j)):.6f} {modulus:.6f}")
    write_atomic(data, "\n".join(lines) + "\n")
    nx = MODEL_ELEMENTS[0]
    png = os.path.join(folder, stem + ".png")
    script = map_preamble(png, 520, 2, title, MODEL_ELEMENTS, HEIGHT / LENGTH,
                          f"element column (x, {1000 * LENGTH / nx:.2f} mm each)") + \
        f"""set title "truth: element modulus in series / 200 GPa"
plot "{data}" using 1:2:3 with image notitle
set title "{panel} / 200 GPa"
plot "{data}" using 1:2:4 with image notitle
unset multiplot
"""
    subprocess.run(["gnuplot"], input=script, text=True, check=True)
    os.replace(png + ".tmp", png)
    os.remove(data)


def run_elements(build_dir, results, case, free, stem, functional="mcre"):
    """identify run of `functional` on `case` per element (ELEMENT_UPDATE_SETTINGS;
    least squares with its adjoint gradient), `free` the elements free and the others
    tied (empty: every element free); keeps <case>/<stem>_zones.csv and draws
    <case>/<stem>.png. Returns the rows of its table."""
    truth, manifest, snr = case
    out = os.path.join(results, case_name(*case))
    settings = ([f"model.free_zones=[{','.join(free)}]"] if free else []) + \
        ELEMENT_UPDATE_SETTINGS
    if functional == "least_squares":
        settings.append("zone_identification.least_squares_gradient=adjoint")
    with tempfile.TemporaryDirectory() as work:
        run, seconds = run_case(build_dir, work, truth, manifest, snr, functional,
                                settings=settings, suffix="_" + stem)
        target = os.path.join(out, stem + "_zones.csv")
        copy_atomic(os.path.join(run, "zones.csv"), target)
        evaluations = zone_evaluations(run)
    if free:
        title, panel = ("localise by the error map, then update per element",
                        "per-element update of the flagged zones (the others tied)")
    elif functional == "least_squares":
        title, panel = "every element's modulus, least squares", "least squares per element"
    else:
        title, panel = "every element's modulus", "identified per element"
    write_element_maps(out, target, truth, case_title(*case) + ": " + title, stem, panel)
    print(f"    {seconds:.0f} s", flush=True)
    return element_table_rows(case_name(*case), target, truth, evaluations, seconds)


def run_element_update(build_dir, results):
    """The per-element update on each of ELEMENT_UPDATE_CASES: every element of the zones
    its map flags free, the rest tied; <case>/element_update_zones.csv and .png, and
    element_update.csv."""
    rows = []
    for case in ELEMENT_UPDATE_CASES:
        flagged = set(map_flagged(os.path.join(results, case_name(*case), "zones.csv")))
        free = [f"element{e}" for e, (i, j) in enumerate(element_positions())
                if zone_of_element(i, j) in flagged]
        print(f"[element update] {case_name(*case)}: the {len(free)} elements of the "
              f"{len(flagged)} flagged zones free, the rest tied, total variation ...",
              flush=True)
        rows += run_elements(build_dir, results, case, free, "element_update")
    write_atomic(os.path.join(results, "element_update.csv"),
                 "\n".join([ELEMENT_HEADER] + rows) + "\n")


def per_element_stem(functional):
    return "per_element" if functional == "mcre" else "per_element_least_squares"


def run_per_element(build_dir, results, functionals=FUNCTIONALS):
    """The whole plate per element on PER_ELEMENT_CASE (576 moduli, no localisation), by
    each of `functionals`: <case>/<stem>_zones.csv and .png, and <stem>.csv (its 64 zones
    in series), stem per_element (the MCRE) or per_element_least_squares."""
    for functional in functionals:
        stem = per_element_stem(functional)
        print(f"[per element] {case_name(*PER_ELEMENT_CASE)}, {functional}: every element "
              "free, total variation ...", flush=True)
        rows = run_elements(build_dir, results, PER_ELEMENT_CASE, [], stem, functional)
        write_atomic(os.path.join(results, stem + ".csv"),
                     "\n".join([ELEMENT_HEADER] + rows) + "\n")


def draw_case(results, truth, manifest, snr):
    out = os.path.join(results, case_name(truth, manifest, snr))
    zones, _ = analyse(os.path.join(out, "zones.csv"), truth)
    ls_path = os.path.join(out, zones_file("least_squares"))
    ls_zones = analyse(ls_path, truth)[0] if os.path.exists(ls_path) else None
    write_maps(out, zones, ls_zones, case_title(truth, manifest, snr))


def parse_functionals(options, expected):
    """The functionals `[--functional mcre|least_squares|both]` names (none: both); exits
    naming the options and `expected` for anything else."""
    if options[:1] == ["--functional"] and len(options) == 2 and options[1] != "both":
        if options[1] not in FUNCTIONALS:
            sys.exit(f"--functional: expected mcre, least_squares or both, got '{options[1]}'")
        return (options[1],)
    if options and options != ["--functional", "both"]:
        sys.exit(f"unknown options {options}{expected}")
    return FUNCTIONALS


def main():
    build_dir, results = sys.argv[1], sys.argv[2]
    options = sys.argv[3:]
    if options == ["--update-only"]:
        run_update(build_dir, results)
        write_summary(results)
        return
    if options == ["--element-update-only"]:
        run_element_update(build_dir, results)
        write_summary(results)
        return
    if options[:1] == ["--per-element-only"]:
        functionals = parse_functionals(
            options[1:], " after --per-element-only: expected [--functional mcre|least_squares|"
            "both]")
        run_per_element(build_dir, results, functionals)
        write_summary(results)
        return
    if options == ["--figures-only"]:
        # cases.csv's measures again from the kept zone files (its times and evaluations
        # kept), then the figures and summary.md.
        rows = []
        for row in read_cases(results):
            truth, manifest, snr = next(c for c in CASES if case_name(*c) == row["case"])
            _, m = analyse(os.path.join(results, row["case"], zones_file(row["functional"])),
                           truth)
            rows.append(case_row(row["case"], row["functional"], truth, manifest, snr, m,
                                 row["zone_evaluations"], float(row["wall_time_s"])))
        write_cases(results, rows)
        for case in CASES:
            draw_case(results, *case)
        write_summary(results)
        print(f"drew {len(CASES)} maps.png and summary.md in {results}")
        return
    functionals = parse_functionals(
        options, ": expected [--functional mcre|least_squares|both], --figures-only, "
        "--update-only, --element-update-only or --per-element-only")
    os.makedirs(results, exist_ok=True)
    rows = [r for r in read_cases(results) if r["functional"] not in functionals]
    runs = [(c, f) for c in CASES for f in functionals]
    with tempfile.TemporaryDirectory() as work:
        for n, ((truth, manifest, snr), functional) in enumerate(runs, 1):
            name = case_name(truth, manifest, snr)
            print(f"[{n}/{len(runs)}] {name}, {functional} ...", flush=True)
            run, seconds = run_case(build_dir, work, truth, manifest, snr, functional)
            out = os.path.join(results, name)
            os.makedirs(out, exist_ok=True)
            kept_files = [("zones.csv", zones_file(functional))]
            if functional == "mcre":
                kept_files.append(("error_map.csv", "error_map.csv"))
            for source, target in kept_files:
                copy_atomic(os.path.join(run, source), os.path.join(out, target))
            evaluations = zone_evaluations(run)
            _, m = analyse(os.path.join(out, zones_file(functional)), truth)
            print(f"    {seconds:.0f} s: {m['found_by_moduli']} / {m['changed_zones']} changed "
                  f"zones found by the moduli; changed zones within "
                  f"{m['changed_worst_error']:.3f} of the series truth, the others within "
                  f"{m['other_worst_error']:.4f}", flush=True)
            rows.append(case_row(name, functional, truth, manifest, snr, m, evaluations, seconds))
    write_cases(results, rows)
    if "mcre" in functionals:
        run_update(build_dir, results)
        run_element_update(build_dir, results)
    run_per_element(build_dir, results, functionals)
    for case in CASES:
        draw_case(results, *case)
    write_summary(results)
    print(f"wrote {results}/cases.csv, summary.md and {len(CASES)} case folders")


if __name__ == "__main__":
    main()
