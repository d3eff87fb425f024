#!/usr/bin/env python3
"""The basin of attraction of the MCRE and of least squares on the 64 zones of the
many-zone plate (the soft inclusion; issue 42's basin study on the 16 x 4 grid,
docs/matrix_models.md section 17), for each case of CASES: full-field data at SNR 10
(configs/plate_zones.yaml) and 20 strain gauges at SNR 20 (configs/plate_zones_gauges.yaml).

    /usr/bin/python3 scripts/plate_zones_basin_study.py BUILD_DIR RESULTS_DIR
        [--case full_field|gauges|both]
        [--functional mcre|least_squares|both | --continuation-only | --figures-only]

Each case writes RESULTS_DIR/<case>/. --case: the cases to run (default both);
--functional: the functional to run again (the other's rows are kept; the continuation
runs with the MCRE); --continuation-only: the continuation alone, from the kept
basin.csv and basin_zones.csv; --figures-only: no run, the figures and summary.md drawn
again from the kept CSV files.

For each functional (outer.functional mcre and least_squares), bounds 50 to 800 GPa, no
uncertainty estimate, `identify run` on the case's config:
  1. from the truth (zone_identification.start_moduli: each zone's modulus in series of
     the truth's fine elements under it, no homogeneous stage) with the config's total
     variation and its weight rule; the weight it keeps (summary.yaml
     regularization_weight) is the functional's weight for the runs below;
  2. from the truth again at that fixed weight: the reference;
  3. from each homogeneous start k E, k in 0.5, 0.6, 0.7, 0.8, 1.25, 1.5, 1.75, 2
     (zone_identification.start_modulus), at the same fixed weight.
A start reaches the truth's basin when every zone ends within 5 % of the reference's
modulus for that zone (the 8-zone study's rule). The two functionals run side by side,
one process each; the runs are deterministic whatever runs beside them, their wall times
are not. Then continuation in the data weight (Banerjee et al., CMAME 2013) on the MCRE:
from 0.5 E and from 2 E, the zones at w_u = w_e = 1e-4, then 1e-3, then the config's
1e-2, each stage from the last one's moduli, at the same fixed penalty weight, against
the fixed data weight's run from the same start.

Writes, per case, basin.csv (a row per functional and start: the weight, the largest
distance to the reference, in the basin or not, the worst error against the truth in
series, the zone evaluations, the wall time, and the run's message when identify refused
it), basin_zones.csv (every run's 64 moduli), histories.csv (every run's cost per zone
evaluation), continuation.csv (a row per start and stage), summary.md, basin.png
(distance to the reference and evaluations per start) and histories.png (the cost
histories: each cost over the run's last one, less 1). Prints progress; the files are
written atomically.
"""

import csv
import os
import re
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plate_zones_geometry import NOMINAL_MODULUS  # noqa: E402
from plate_zones_study import (GRID, ROOT, relative_moduli, truth_of_zones,  # noqa: E402
                               write_atomic, zone_evaluations)

STARTS = [0.5, 0.6, 0.7, 0.8, 1.25, 1.5, 1.75, 2.0]  # k: every zone starts at k E
BASIN_TOLERANCE = 0.05  # every zone within 5 % of its from-the-truth modulus
FUNCTIONALS = ("mcre", "least_squares")
TRUTH = "soft_inclusion"  # both configs' truth
# Per case: its config, a title and what its data are.
CASES = {
    "full_field": ("plate_zones.yaml", "full-field data",
                   "full-field data (u_x, u_y at every free node), SNR 10"),
    "gauges": ("plate_zones_gauges.yaml", "20 strain gauges",
               "its 20 strain gauges chosen by D-optimal design, SNR 20"),
}
# Zone order of the model (RegroupedElementZones: the column index runs fastest).
ZONES = [f"grid_{i}_{j}" for j in range(GRID[1]) for i in range(GRID[0])]
SETTINGS = ["outer.lower_bound=50e9", "outer.upper_bound=800e9", "uncertainty.samples=0",
            "zone_identification.max_time=7200", "output.figures=false",
            "output.curve_points=5"]


def side_by_side(task, arguments):
    """task(*a) for each a of `arguments`, one thread each (each runs identify processes);
    exits with their messages when any of them exits."""
    failures = []

    def worker(a):
        try:
            task(*a)
        except SystemExit as error:
            failures.append(str(error))

    threads = [threading.Thread(target=worker, args=(a,)) for a in arguments]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    if failures:
        sys.exit("\n".join(failures))


def identify(build_dir, case, folder, functional, settings):
    """One identify run of `case` into `folder`. Returns (ok, seconds, message): message
    the last line of its error output when it exits non-zero."""
    command = [os.path.join(build_dir, "identify", "identify"), "run",
               os.path.join(ROOT, "configs", CASES[case][0]), "-q", "-o", folder,
               "--set", f"outer.functional={functional}"]
    for setting in SETTINGS + settings:
        command += ["--set", setting]
    start = time.monotonic()
    done = subprocess.run(command, capture_output=True, text=True)
    seconds = time.monotonic() - start
    if done.returncode == 0:
        return True, seconds, ""
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    return False, seconds, lines[-1] if lines else f"exit code {done.returncode}"


def kept_weight(folder):
    """The regularisation weight an identify run's summary.yaml reports."""
    text = open(os.path.join(folder, "summary.yaml")).read()
    found = re.search(r"^\s*regularization_weight:\s*(\S+)", text, re.M)
    if not found:
        sys.exit(f"{folder}/summary.yaml: no regularization_weight")
    return float(found.group(1))


def history(folder):
    """The cost of each usable zone evaluation of a run (zone_evaluations.csv's
    scaled_cost, the penalty included)."""
    path = os.path.join(folder, "zone_evaluations.csv")
    return [float(r["scaled_cost"]) for r in csv.DictReader(open(path)) if r["usable"] == "1"]


def read_histories(output):
    """histories.csv's costs per (functional, start), in its order; start 'truth' or k."""
    histories = {}
    for r in csv.DictReader(open(os.path.join(output, "histories.csv"))):
        start = r["start"] if r["start"] == "truth" else float(r["start"])
        histories.setdefault((r["functional"], start), []).append(float(r["cost"]))
    return histories


def run_functional(build_dir, case, work, functional, truths, rows, moduli, histories, lock):
    """Steps 1 to 3 for one functional; appends its basin.csv rows, moduli and histories."""
    truth_start = "zone_identification.start_moduli=[" + ",".join(
        f"{truths[z][0] * NOMINAL_MODULUS:.17g}" for z in ZONES) + "]"
    tag = functional.replace("_", " ")
    print(f"[{tag}] from the truth, the weight rule ...", flush=True)
    folder = os.path.join(work, functional + "_rule")
    ok, seconds, message = identify(build_dir, case, folder, functional, [truth_start])
    if not ok:
        sys.exit(f"[{tag}] the weight rule's run from the truth was refused: {message}")
    weight = kept_weight(folder)
    print(f"[{tag}] weight {weight:.3g} kept ({seconds:.0f} s)", flush=True)
    fixed = f"zone_identification.regularization_weight={weight:.17g}"
    reference = None
    for start in ["truth"] + STARTS:
        setting = truth_start if start == "truth" else \
            f"zone_identification.start_modulus={start * NOMINAL_MODULUS:.17g}"
        folder = os.path.join(work, f"{functional}_{start}")
        ok, seconds, message = identify(build_dir, case, folder, functional, [setting, fixed])
        row = {"functional": functional, "start": start, "weight": weight,
               "wall_time_s": seconds, "message": message}
        if ok:
            found = relative_moduli(os.path.join(folder, "zones.csv"))
            costs = history(folder)
            if reference is None:
                reference = found
            row["distance"] = max(abs(found[z] / reference[z] - 1.0) for z in ZONES)
            row["truth_error"] = max(abs(found[z] / truths[z][0] - 1.0) for z in ZONES)
            row["evaluations"] = zone_evaluations(folder)
            with lock:
                moduli[(functional, start)] = found
                histories[(functional, start)] = costs
        elif reference is None:
            sys.exit(f"[{tag}] the fixed weight's run from the truth was refused: {message}")
        row["in_basin"] = ok and row["distance"] <= BASIN_TOLERANCE
        print(f"[{tag}] from {start if start == 'truth' else f'{start:g} E'}: " +
              (f"{row['evaluations']} evaluations, {seconds:.0f} s, every zone within "
               f"{100 * row['distance']:.2f} % of the reference" if ok else
               f"refused: {message}"), flush=True)
        with lock:
            rows.append(row)


CONTINUATION_WEIGHTS = [1e-4, 1e-3, 1e-2]  # w_u = w_e of each stage, the last the config's
CONTINUATION_STARTS = [0.5, 2.0]


def run_continuation(build_dir, case, output):
    """Continuation in the data weight (Banerjee et al., CMAME 2013) on the MCRE: from each
    of CONTINUATION_STARTS, the zones at w_u = w_e = 1e-4, then 1e-3, then the config's
    1e-2, each stage from the last one's moduli (start_moduli), at the fixed total
    variation weight of basin.csv, against the fixed data weight's run from the same start
    (basin.csv, basin_zones.csv). Writes continuation.csv."""
    basin = [r for r in csv.DictReader(open(os.path.join(output, "basin.csv")))
             if r["functional"] == "mcre"]
    if not basin:
        sys.exit(f"{output}/basin.csv: no MCRE rows; run the basin step first")
    weight = float(basin[0]["regularization_weight"])
    fixed_moduli = list(csv.DictReader(open(os.path.join(output, "basin_zones.csv"))))
    lines, lock = {}, threading.Lock()

    def from_start(start, work):
        fixed = next(r for r in basin if r["start"] != "truth" and float(r["start"]) == start)
        column = next((k for k in fixed_moduli[0] if k.startswith("mcre_") and
                       k != "mcre_truth" and float(k[5:]) == start), None)
        if column is None:
            sys.exit(f"[continuation] the fixed weight's run from {start:g} E was refused "
                     f"({fixed['message']}): no moduli to compare with")
        reference = {r["zone"]: float(r[column]) for r in fixed_moduli}
        setting = f"zone_identification.start_modulus={start * NOMINAL_MODULUS:.17g}"
        total = 0
        rows = []
        for stage, data_weight in enumerate(CONTINUATION_WEIGHTS, 1):
            folder = os.path.join(work, f"continuation_{start:g}_{stage}")
            ok, seconds, message = identify(
                build_dir, case, folder, "mcre",
                [setting, f"zone_identification.regularization_weight={weight:.17g}",
                 f"mcre.w_u={data_weight:g}", f"mcre.w_e={data_weight:g}"])
            if not ok:
                sys.exit(f"[continuation] from {start:g} E, stage {stage}: refused: {message}")
            found = relative_moduli(os.path.join(folder, "zones.csv"))
            evaluations = zone_evaluations(folder)
            total += evaluations
            distance = max(abs(found[z] / reference[z] - 1.0) for z in ZONES)
            print(f"[continuation] from {start:g} E, w = {data_weight:g}: {evaluations} "
                  f"evaluations, {seconds:.0f} s, every zone within {100 * distance:.2f} % of "
                  "the fixed weight's moduli", flush=True)
            rows.append(f"{start:g},{stage},{data_weight:g},{evaluations},{total},"
                        f"{fixed['zone_evaluations']},{distance:.6f},{seconds:.1f}")
            setting = "zone_identification.start_moduli=[" + ",".join(
                f"{found[z] * NOMINAL_MODULUS:.17g}" for z in ZONES) + "]"
        with lock:
            lines[start] = rows

    with tempfile.TemporaryDirectory() as work:
        side_by_side(from_start, [(s, work) for s in CONTINUATION_STARTS])
    text = ["start,stage,data_weight,zone_evaluations,cumulative_evaluations,"
            "fixed_weight_evaluations,max_distance_to_fixed_weight,wall_time_s"]
    for start in CONTINUATION_STARTS:
        text += lines[start]
    write_atomic(os.path.join(output, "continuation.csv"), "\n".join(text) + "\n")


def number(value, digits):
    return "" if value is None else f"{value:.{digits}g}"


def write_tables(output, rows, moduli, histories, truths):
    order = {f: n for n, f in enumerate(FUNCTIONALS)}
    rows.sort(key=lambda r: (order[r["functional"]], -1 if r["start"] == "truth" else
                             r["start"]))
    lines = ["functional,start,regularization_weight,max_distance_to_reference,in_basin,"
             "max_error_to_truth_series,zone_evaluations,wall_time_s,message"]
    for r in rows:
        lines.append(f"{r['functional']},{r['start']},{r['weight']:.6g},"
                     f"{number(r.get('distance'), 6)},{str(r['in_basin']).lower()},"
                     f"{number(r.get('truth_error'), 6)},{r.get('evaluations', '')},"
                     f"{r['wall_time_s']:.1f},\"{r['message'].replace(chr(34), chr(39))}\"")
    write_atomic(os.path.join(output, "basin.csv"), "\n".join(lines) + "\n")
    runs = [(r["functional"], r["start"]) for r in rows if (r["functional"], r["start"]) in moduli]
    lines = ["zone,truth_series," + ",".join(f"{f}_{s}" for f, s in runs)]
    for z in ZONES:
        lines.append(f"{z},{truths[z][0]:.6f}," +
                     ",".join(f"{moduli[run][z]:.6f}" for run in runs))
    write_atomic(os.path.join(output, "basin_zones.csv"), "\n".join(lines) + "\n")
    lines = ["functional,start,evaluation,cost"]
    for run in runs:
        lines += [f"{run[0]},{run[1]},{n},{c:.10g}" for n, c in enumerate(histories[run], 1)]
    write_atomic(os.path.join(output, "histories.csv"), "\n".join(lines) + "\n")


def plot(case, output):
    """basin.png and histories.png from basin.csv and histories.csv (gnuplot)."""
    rows = list(csv.DictReader(open(os.path.join(output, "basin.csv"))))
    data = os.path.join(output, "basin.dat")
    lines = []
    for functional in FUNCTIONALS:
        lines.append(f"# {functional}: start_E distance_percent evaluations refused_marker")
        for r in rows:
            if r["functional"] == functional and r["start"] != "truth":
                distance = r["max_distance_to_reference"]
                lines.append(f"{r['start']} {100 * float(distance) if distance else 'NaN'} "
                             f"{r['zone_evaluations'] or 'NaN'} {'NaN' if distance else 50}")
        lines += ["", ""]
    write_atomic(data, "\n".join(lines) + "\n")
    png = os.path.join(output, "basin.png")
    script = f"""set terminal pngcairo size 1000,420 font ",10"
set output "{png}.tmp"
set multiplot layout 1,2 title "64 zones of the plate (soft inclusion; {CASES[case][2]}): homogeneous starts" noenhanced
set logscale x
set xrange [0.45:2.2]
set xtics (0.5, 0.6, 0.7, 0.8, 1, 1.25, 1.5, 1.75, 2)
set xlabel "start / 200 GPa"
set logscale y
set ylabel "largest zone distance to the from-truth moduli [%]"
set yrange [1e-6:500]
set format y "%g"
set key bottom right font ",9"
plot "{data}" index 0 using 1:2 with linespoints pt 7 lc 1 title "MCRE", \\
     "{data}" index 1 using 1:2 with linespoints pt 5 lc 2 title "least squares", \\
     "{data}" index 0 using 1:4 with points pt 6 ps 2 lc 1 title "MCRE: refused, a zone on a bound", \\
     "{data}" index 1 using 1:4 with points pt 4 ps 2 lc 2 title "least squares: refused, a zone on a bound", \\
     {100 * BASIN_TOLERANCE} with lines dt 2 lc rgb "black" title "basin: 5 %"
unset logscale y
set ylabel "zone evaluations"
set yrange [0:*]
set format y "%g"
set key bottom right
plot "{data}" index 0 using 1:3 with linespoints pt 7 title "MCRE", \\
     "{data}" index 1 using 1:3 with linespoints pt 5 title "least squares"
unset multiplot
"""
    subprocess.run(["gnuplot"], input=script, text=True, check=True)
    os.replace(png + ".tmp", png)
    os.remove(data)

    histories = read_histories(output)
    data = os.path.join(output, "histories.dat")
    blocks, plots = [], []
    for (functional, start), costs in histories.items():  # basin.csv's order
        # The cost over its run's last one, less 1, down to 1e-9 (where L-BFGS polishes).
        blocks.append("\n".join(f"{n} {max(c / costs[-1] - 1.0, 1e-9):.6g}"
                                for n, c in enumerate(costs, 1)))
        plots.append((functional, start, len(blocks) - 1))
    write_atomic(data, "\n\n\n".join(blocks) + "\n")
    png = os.path.join(output, "histories.png")
    panels = []
    for functional, title in (("mcre", "MCRE"), ("least_squares", "least squares")):
        curves = [f'"{data}" index {i} using 1:2 with lines lw {2 if s == "truth" else 1} '
                  f'title "{"truth" if s == "truth" else f"{s:g} E"}"'
                  for f, s, i in plots if f == functional]
        if curves:
            panels.append(f'set title "{title}"\nplot ' + ", \\\n     ".join(curves))
    script = f"""set terminal pngcairo size 1000,420 font ",10"
set output "{png}.tmp"
set multiplot layout 1,2 title "convergence: the cost at each zone evaluation over the run's last cost, less 1"
set logscale y
set yrange [1e-9:*]
set format y "10^{{%L}}"
set xlabel "zone evaluation"
set ylabel "cost / last cost - 1"
set key top right
""" + "\n".join(panels) + "\nunset multiplot\n"
    subprocess.run(["gnuplot"], input=script, text=True, check=True)
    os.replace(png + ".tmp", png)
    os.remove(data)


def write_summary(case, output):
    rows = list(csv.DictReader(open(os.path.join(output, "basin.csv"))))
    config, title, data = CASES[case]
    md = [f"# The basin of attraction on the plate's 64 zones, {title} "
          "(scripts/plate_zones_basin_study.sh)",
          "", f"configs/{config} (48 x 12 Q4 model, 16 x 4 zones, the soft inclusion "
          f"at 0.7 E, {data}), bounds 50 to 800 GPa, total variation at the "
          "weight each functional's rule keeps from the truth's zone moduli. A start reaches "
          "the truth's basin when every zone ends within 5 % of what the same functional "
          "reaches from the truth at that weight. Errors to the truth: the largest over the "
          "zones against the zone's modulus in series. basin.csv, basin_zones.csv (every "
          "run's moduli), histories.csv; basin.png, histories.png.", "",
          "| functional | weight | starts in the truth's basin | zone evaluations (from the "
          "truth; mean over the starts in the basin) | largest error to the truth (from the "
          "truth) | not in the basin |", "|---|---|---|---|---|---|"]
    for functional in FUNCTIONALS:
        mine = [r for r in rows if r["functional"] == functional]
        if not mine:
            continue
        reference = mine[0]
        starts = [r for r in mine if r["start"] != "truth"]
        inside = [r for r in starts if r["in_basin"] == "true"]
        outside = ", ".join(
            f"{float(r['start']):g} E (" + (f"{100 * float(r['max_distance_to_reference']):.0f} %"
                                           if r["max_distance_to_reference"] else
                                           "refused") + ")"
            for r in starts if r["in_basin"] != "true") or "none"
        mean = (sum(int(r["zone_evaluations"]) for r in inside) / len(inside)) if inside else 0
        md.append(f"| {functional.replace('_', ' ')} | {float(reference['regularization_weight']):.3g} "
                  f"| {len(inside)} of {len(starts)} | {reference['zone_evaluations']}; "
                  f"{mean:.1f} | {100 * float(reference['max_error_to_truth_series']):.1f} % "
                  f"| {outside} |")
    md += ["", "| functional | start | largest distance to the from-truth moduli | in the basin "
           "| zone evaluations | time [s] | message |", "|---|---|---|---|---|---|---|"]
    for r in rows:
        distance = r["max_distance_to_reference"]
        start = r["start"] if r["start"] == "truth" else f"{float(r['start']):g} E"
        md.append(f"| {r['functional'].replace('_', ' ')} | {start} | "
                  f"{f'{100 * float(distance):.2f} %' if distance else '-'} | "
                  f"{'yes' if r['in_basin'] == 'true' else 'no'} | {r['zone_evaluations'] or '-'} | "
                  f"{float(r['wall_time_s']):.0f} | {r['message'] or ''} |")
    continuation = os.path.join(output, "continuation.csv")
    if os.path.exists(continuation):
        stages = list(csv.DictReader(open(continuation)))
        md += ["", "Continuation in the data weight (MCRE): the zones at w_u = w_e = 1e-4, then "
               "1e-3, then the config's 1e-2, each stage from the last one's moduli, at the "
               "same total variation weight, against the fixed data weight from the same start "
               "(continuation.csv).", "",
               "| start | zone evaluations per stage | continuation in all | fixed weight | "
               "last stage: largest distance to the fixed weight's moduli |",
               "|---|---|---|---|---|"]
        for start in dict.fromkeys(r["start"] for r in stages):
            mine = [r for r in stages if r["start"] == start]
            md.append(f"| {start} E | {', '.join(r['zone_evaluations'] for r in mine)} | "
                      f"{mine[-1]['cumulative_evaluations']} | "
                      f"{mine[-1]['fixed_weight_evaluations']} | "
                      f"{100 * float(mine[-1]['max_distance_to_fixed_weight']):.2f} % |")
    md += ["", "The two functionals ran side by side, one process each on a core of their own "
           "(the two starts of the continuation likewise); the times are wall times.", ""]
    write_atomic(os.path.join(output, "summary.md"), "\n".join(md))


def read_kept(output, functionals):
    """basin.csv's rows, basin_zones.csv's moduli and histories.csv's costs of the
    functionals not in `functionals` (kept when one functional runs again)."""
    rows, moduli, histories = [], {}, {}
    if not os.path.exists(os.path.join(output, "basin.csv")):
        return rows, moduli, histories

    def start_of(text):
        return text if text == "truth" else float(text)

    for r in csv.DictReader(open(os.path.join(output, "basin.csv"))):
        if r["functional"] in functionals:
            continue
        row = {"functional": r["functional"], "start": start_of(r["start"]),
               "weight": float(r["regularization_weight"]),
               "wall_time_s": float(r["wall_time_s"]), "message": r["message"],
               "in_basin": r["in_basin"] == "true"}
        if r["max_distance_to_reference"]:
            row.update(distance=float(r["max_distance_to_reference"]),
                       truth_error=float(r["max_error_to_truth_series"]),
                       evaluations=int(r["zone_evaluations"]))
        rows.append(row)
    columns = list(csv.DictReader(open(os.path.join(output, "basin_zones.csv"))))
    for key in columns[0]:
        functional = next((f for f in FUNCTIONALS if key.startswith(f + "_")), None)
        if functional and functional not in functionals:
            moduli[(functional, start_of(key[len(functional) + 1:]))] = {
                c["zone"]: float(c[key]) for c in columns}
    histories = {key: costs for key, costs in read_histories(output).items()
                 if key[0] not in functionals}
    return rows, moduli, histories


USAGE = ("usage: plate_zones_basin_study.py BUILD_DIR RESULTS_DIR [--case full_field|gauges|both] "
         "[--functional mcre|least_squares|both | --continuation-only | --figures-only]")


def parse(options):
    """(cases, functionals, step) from the options after the two folders; step: 'all',
    'continuation' or 'figures'."""
    cases, functionals, step = tuple(CASES), FUNCTIONALS, "all"
    values = {"--case": tuple(CASES) + ("both",), "--functional": FUNCTIONALS + ("both",)}
    n = 0
    while n < len(options):
        option = options[n]
        if option in values:
            if n + 1 == len(options) or options[n + 1] not in values[option]:
                sys.exit(f"{option}: expected one of {', '.join(values[option])}; " + USAGE)
            value = options[n + 1]
            if option == "--case":
                cases = tuple(CASES) if value == "both" else (value,)
            else:
                functionals = FUNCTIONALS if value == "both" else (value,)
            n += 2
        elif option in ("--continuation-only", "--figures-only") and step == "all":
            step = option[2:].split("-")[0]
            n += 1
        else:
            sys.exit(f"unknown option '{option}'; " + USAGE)
    return cases, functionals, step


def main():
    if len(sys.argv) < 3:
        sys.exit(USAGE)
    build_dir, results = sys.argv[1:3]
    cases, functionals, step = parse(sys.argv[3:])
    for case in cases:
        output = os.path.join(results, case)
        print(f"== {case}: {CASES[case][2]}", flush=True)
        if step == "continuation":
            run_continuation(build_dir, case, output)
        elif step == "all":
            os.makedirs(output, exist_ok=True)
            truths = truth_of_zones(TRUTH)
            rows, moduli, histories = read_kept(output, functionals)
            lock = threading.Lock()
            with tempfile.TemporaryDirectory() as work:
                side_by_side(run_functional, [(build_dir, case, work, f, truths, rows, moduli,
                                               histories, lock) for f in functionals])
            write_tables(output, rows, moduli, histories, truths)
            if "mcre" in functionals:
                run_continuation(build_dir, case, output)
        plot(case, output)
        write_summary(case, output)
        print(f"wrote {output}: basin.csv, basin_zones.csv, histories.csv, continuation.csv, "
              "summary.md, basin.png and histories.png", flush=True)


if __name__ == "__main__":
    main()
