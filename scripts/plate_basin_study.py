"""The basin of attraction of the MCRE and of least squares on the 8 zones of the SfePy
plate of examples/plate_with_sfepy.py (issue 42's basin study, on 8 zones).

    PYTHONPATH=build /usr/bin/python3 scripts/plate_basin_study.py OUTPUT_FOLDER

The plate, its truth (one zone at 0.7 E), its 8 strain gauges and their data at SNR 20
are the example's. For each functional (outer.functional mcre and least_squares), the
8 zones are identified:
  - from the truth: the model's nominal moduli the truth's zone moduli (zones start
    there, no homogeneous stage);
  - from each homogeneous start k E, k in 0.5, 0.6, 0.7, 0.8, 1.25, 1.5, 1.75, 2
    (zone_identification.start_modulus, no homogeneous stage).
A start reaches the truth's basin when every zone ends within 5 % of what the same
functional reaches from the truth. Then continuation in the data weight (Banerjee et al.,
CMAME 2013): from 0.5 E and from 2 E, the MCRE's zones at w_u = w_e = 1e-4, then 1e-3,
then the config's 1e-2, each stage starting from the last one's moduli (the model's
nominal moduli), against the fixed weight 1e-2 from the same start. Writes basin.csv (a
row per functional and start: the zones' moduli, the largest distance to the from-truth
moduli, the evaluations, the wall time, in the basin or not), continuation.csv (a row
per start and stage), summary.md and basin.png. Needs the mcrewave module,
SfePy and matplotlib (scripts/plate_basin_study.sh installs them).
"""

import csv
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "examples"))

import plate_with_sfepy as example  # noqa: E402  (its plate, truth, gauges and data)

example.sfepy_output.set_output(quiet=True)
import mcrewave  # noqa: E402

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

STARTS = [0.5, 0.6, 0.7, 0.8, 1.25, 1.5, 1.75, 2.0]  # k: every zone starts at k E
BASIN_TOLERANCE = 0.05  # every zone within 5 % of its from-truth modulus
FUNCTIONALS = ["mcre", "least_squares"]
SNR = 20.0
SEED = 1


CONTINUATION_WEIGHTS = [1e-4, 1e-3, 1e-2]  # w_u = w_e of each stage, the last the config's
CONTINUATION_STARTS = [0.5, 2.0]


def config_of(functional, start_modulus, weight=1e-2):
    """The example's config, with bounds that hold every start, for one functional and
    one start (0: the model's nominal moduli), the MCRE's data weights w_u = w_e =
    `weight`."""
    return {
        "time": {"window": example.WINDOW, "step": example.TIME_STEP, "theta": 0.5},
        "mcre": {"w_u": weight, "w_e": weight, "reference_modulus": example.MODULUS},
        "inner": {"method": "streaming_conjugate_gradient", "preconditioner": "dense_traces",
                  "tolerance": 1e-8},
        "outer": {"functional": functional, "lower_bound": 50e9, "upper_bound": 800e9,
                  "scan_threads": 1},
        "zone_identification": {"optimizer": "nlopt", "algorithm": "lbfgs",
                                "regularization": "none", "start_modulus": start_modulus},
        "uncertainty": {"samples": 2},
    }


def main():
    if len(sys.argv) != 2:
        print("usage: plate_basin_study.py OUTPUT_FOLDER", file=sys.stderr)
        return 2
    folder = sys.argv[1]
    try:
        os.makedirs(folder, exist_ok=True)
    except OSError as error:
        print(f"error: cannot make the output folder {folder}: {error.strerror}", file=sys.stderr)
        return 2
    start = time.perf_counter()

    # 1. The example's plate, truth and data.
    model_plate, truth_plate = example.Plate(*example.MODEL_MESH), example.Plate(*example.TRUTH_MESH)
    model_zones = np.array([example.zone_of(x, y) for x, y in model_plate.centroids])
    truth_soft = np.array([example.in_soft_region(x, y) for x, y in truth_plate.centroids],
                          dtype=int)
    truth_moduli = np.array([example.MODULUS, example.SOFT_FACTOR * example.MODULUS])
    truth = example.mcrewave_model(truth_plate, truth_soft, ["sound", "soft"], "the truth")
    zone_truth = example.zone_truth_moduli(truth_plate, truth_soft, truth_moduli)
    data = example.gauge_measurements(truth, truth_moduli, SNR, SEED)
    nominal = example.mcrewave_model(model_plate, model_zones, example.ZONE_NAMES, "the model")
    from_truth_model = example.mcrewave_model(model_plate, model_zones, example.ZONE_NAMES,
                                              "the model at the truth's moduli",
                                              nominal_moduli=zone_truth)

    # 2. Every functional from the truth, then from each homogeneous start.
    rows = []
    for functional in FUNCTIONALS:
        runs = [("truth", from_truth_model, 0.0)]
        runs += [(f"{k:g} E", nominal, k * example.MODULUS) for k in STARTS]
        reference = None
        for label, model, start_modulus in runs:
            began = time.perf_counter()
            try:
                result = mcrewave.identify(config_of(functional, start_modulus), model, data,
                                           quiet=True)
                moduli = np.asarray(result.moduli)
                evaluations = result.summary["zones"]["evaluations"]
                failure = ""
            except mcrewave.IdentificationError as error:
                moduli = np.asarray(error.result.moduli)
                evaluations = error.result.evaluations_count
                failure = str(error)
            seconds = time.perf_counter() - began
            if reference is None:
                reference = moduli
            distance = (np.max(np.abs(moduli / reference - 1.0)) if moduli.size == reference.size
                        else float("nan"))
            in_basin = not failure and distance <= BASIN_TOLERANCE
            rows.append({"functional": functional, "start": label, "start_modulus": start_modulus,
                         "moduli": moduli, "distance": distance, "in_basin": in_basin,
                         "evaluations": evaluations, "seconds": seconds, "failure": failure,
                         "error_to_truth": (np.max(np.abs(moduli / zone_truth - 1.0))
                                            if moduli.size == zone_truth.size else float("nan"))})
            print(f"{functional:13s} from {label:7s}: largest distance to the from-truth moduli "
                  f"{100 * distance:7.2f} %, to the truth {100 * rows[-1]['error_to_truth']:6.2f} %,"
                  f" {evaluations} evaluations, {seconds:.1f} s {failure}", flush=True)

    # 3. Continuation in the data weight against the fixed weight, from two starts.
    stages = []
    for k in CONTINUATION_STARTS:
        fixed = next(row for row in rows
                     if row["functional"] == "mcre" and row["start_modulus"] == k * example.MODULUS)
        moduli = None
        for weight in CONTINUATION_WEIGHTS:
            began = time.perf_counter()
            if moduli is None:
                result = mcrewave.identify(config_of("mcre", k * example.MODULUS, weight), nominal,
                                           data, quiet=True)
            else:
                model = example.mcrewave_model(model_plate, model_zones, example.ZONE_NAMES,
                                               "the model at the last stage's moduli",
                                               nominal_moduli=moduli)
                result = mcrewave.identify(config_of("mcre", 0.0, weight), model, data, quiet=True)
            moduli = np.asarray(result.moduli)
            stages.append({"start": k, "weight": weight, "moduli": moduli,
                           "evaluations": result.summary["zones"]["evaluations"],
                           "seconds": time.perf_counter() - began,
                           "distance": np.max(np.abs(moduli / fixed["moduli"] - 1.0)),
                           "fixed_evaluations": fixed["evaluations"],
                           "fixed_seconds": fixed["seconds"]})
            print(f"continuation from {k:g} E, w = {weight:g}: {stages[-1]['evaluations']} "
                  f"evaluations, {stages[-1]['seconds']:.1f} s, "
                  f"{100 * stages[-1]['distance']:.3f} % from the fixed weight's moduli", flush=True)

    # 4. The tables, the summary and the figure.
    with open(os.path.join(folder, "basin.csv.tmp"), "w", newline="") as file:
        writer = csv.writer(file)
        writer.writerow(["functional", "start", "start_modulus_Pa"] +
                        [f"{name}_Pa" for name in example.ZONE_NAMES] +
                        ["distance_to_from_truth", "largest_error_to_truth", "in_basin",
                         "evaluations", "wall_time_s", "failure"])
        for row in rows:
            writer.writerow([row["functional"], row["start"], f"{row['start_modulus']:.6g}"] +
                            [f"{m:.9g}" for m in row["moduli"]] +
                            [f"{row['distance']:.6g}", f"{row['error_to_truth']:.6g}",
                             int(row["in_basin"]), row["evaluations"], f"{row['seconds']:.2f}",
                             row["failure"]])
    os.replace(os.path.join(folder, "basin.csv.tmp"), os.path.join(folder, "basin.csv"))
    with open(os.path.join(folder, "continuation.csv.tmp"), "w", newline="") as file:
        writer = csv.writer(file)
        writer.writerow(["start_k", "weight"] + [f"{name}_Pa" for name in example.ZONE_NAMES] +
                        ["evaluations", "wall_time_s", "distance_to_fixed_weight"])
        for stage in stages:
            writer.writerow([f"{stage['start']:g}", f"{stage['weight']:g}"] +
                            [f"{m:.9g}" for m in stage["moduli"]] +
                            [stage["evaluations"], f"{stage['seconds']:.2f}",
                             f"{stage['distance']:.6g}"])
    os.replace(os.path.join(folder, "continuation.csv.tmp"),
               os.path.join(folder, "continuation.csv"))

    lines = ["# Basin of attraction on the 8 zones of the SfePy plate",
             "",
             "`bash scripts/plate_basin_study.sh` (scripts/plate_basin_study.py): the plate, "
             "truth and data of examples/plate_with_sfepy.py (24 x 6 Q4 model in 4 x 2 zones, "
             "48 x 12 truth with zone_2_0 at 0.7 E, 8 strain gauges, SNR 20, seed 1). Each "
             "functional identifies the 8 zones from the truth and from 8 homogeneous starts "
             "k E (`zone_identification.start_modulus`, no homogeneous stage, bounds 50 to "
             "800 GPa, NLopt L-BFGS without a penalty). A start reaches the truth's basin when "
             "every zone ends within 5 % of what the same functional reaches from the truth.",
             "",
             "| functional | start | largest distance to the from-truth moduli | largest "
             "error to the truth | evaluations | in the basin |",
             "|---|---|---|---|---|---|"]
    for row in rows:
        lines.append(f"| {row['functional']} | {row['start']} | {100 * row['distance']:.2f} % | "
                     f"{100 * row['error_to_truth']:.2f} % | {row['evaluations']} | "
                     f"{'yes' if row['in_basin'] else 'no'} |")
    lines.append("")
    for functional in FUNCTIONALS:
        starts = [row for row in rows if row["functional"] == functional and row["start"] != "truth"]
        reached = sum(row["in_basin"] for row in starts)
        evaluations = [row["evaluations"] for row in starts if row["in_basin"]]
        mean = f"{np.mean(evaluations):.1f}" if evaluations else "-"
        lines.append(f"- {functional}: {reached} of {len(starts)} starts reach the truth's basin "
                     f"(mean evaluations of those: {mean}).")
    lines += ["",
              "Continuation in the data weight (the MCRE, w_u = w_e = 1e-4, 1e-3, then 1e-2, "
              "each stage from the last one's moduli) against the fixed weight 1e-2 from the "
              "same start:",
              "",
              "| start | evaluations per stage | continuation in all | fixed weight | "
              "continuation's end to the fixed weight's moduli |",
              "|---|---|---|---|---|"]
    for k in CONTINUATION_STARTS:
        of_start = [stage for stage in stages if stage["start"] == k]
        lines.append(f"| {k:g} E | {', '.join(str(s['evaluations']) for s in of_start)} | "
                     f"{sum(s['evaluations'] for s in of_start)} "
                     f"({sum(s['seconds'] for s in of_start):.1f} s) | "
                     f"{of_start[-1]['fixed_evaluations']} "
                     f"({of_start[-1]['fixed_seconds']:.1f} s) | "
                     f"{100 * of_start[-1]['distance']:.3f} % |")
    lines.append(f"\nAbout {time.perf_counter() - start:.0f} s on one core.")
    with open(os.path.join(folder, "summary.md.tmp"), "w", encoding="utf-8") as file:
        file.write("\n".join(lines) + "\n")
    os.replace(os.path.join(folder, "summary.md.tmp"), os.path.join(folder, "summary.md"))

    figure, axes = plt.subplots(1, len(FUNCTIONALS), figsize=(11, 4), sharey=True)
    for axis, functional in zip(axes, FUNCTIONALS):
        for row in rows:
            if row["functional"] != functional:
                continue
            x = 1.0 if row["start"] == "truth" else row["start_modulus"] / example.MODULUS
            axis.plot(np.full(row["moduli"].size, x), row["moduli"] / 1e9,
                      "o" if row["in_basin"] else "x",
                      color="tab:blue" if row["start"] != "truth" else "tab:green")
        axis.axhline(example.MODULUS / 1e9, color="gray", lw=0.8)
        axis.axhline(example.SOFT_FACTOR * example.MODULUS / 1e9, color="gray", lw=0.8, ls="--")
        axis.set_xscale("log")
        axis.set_xticks(STARTS + [1.0])
        axis.set_xticklabels([f"{k:g}" for k in STARTS + [1.0]])
        axis.set_xlabel("start k (every zone at k E; 1: from the truth)")
        axis.set_title(f"{functional}: the 8 zones reached")
    axes[0].set_ylabel("zone modulus [GPa]")
    figure.suptitle("Basin of attraction, 8 zones of the SfePy plate (o: in the truth's "
                    "basin, x: not)")
    figure.tight_layout()
    figure.savefig(os.path.join(folder, "basin.tmp.png"), dpi=120)
    os.replace(os.path.join(folder, "basin.tmp.png"), os.path.join(folder, "basin.png"))
    print(f"wrote {folder}/basin.csv, summary.md and basin.png in "
          f"{time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
