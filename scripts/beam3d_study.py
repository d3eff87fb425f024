#!/usr/bin/env python3
"""Regenerates results/beam3d/: the 3-D beam of configs/beam3d.yaml on the one road, what
one coupled solve costs in time and memory as the mesh grows, against the 2-D plates,
and its four zones identified (docs/matrix_models.md section 16).

1. Meshes of the beam written by scripts/make_beam3d_example.py (SfePy) into a
   temporary folder (the larger ones are too big to commit): the committed 24 x 2 x 2
   and MESHES, up to 144 x 6 x 6 (21168 dofs).
2. For each, configs/beam3d.yaml on that mesh, and for the comparison the plates of
   configs/plate.yaml and configs/plate_zones_gauges.yaml with the streaming CG and no
   preconditioner: one coupled solve by bench/streaming_memory_benchmark, each in its
   own process (its resident memory is its own); the largest beam also with its
   retrograde history in checkpoints (a history budget of 16 MB). solve_cost.csv, and
   solve_cost.png: CPU per dof, step and sweep, and the peak resident memory, against
   the dofs.
3. `identify run configs/beam3d.yaml` on the committed mesh: identify/ (summary.yaml,
   zones.csv and the run's figures) and zones.csv beside this study's tables.

Writes summary.md with both tables. Prints progress; files are written atomically.

Usage: /usr/bin/python3 scripts/beam3d_study.py BUILD_DIR RESULTS_DIR [--figure-only]
       --figure-only: redraw solve_cost.png from RESULTS_DIR/solve_cost.csv, nothing run.
"""

import csv
import os
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
MESHES = [(24, 6, 6), (48, 6, 6), (96, 6, 6), (144, 6, 6)]
CHECKPOINT_BYTES = 16 << 20
PLATES = [("plate (2 zones, 5 sensors)", "plate.yaml"),
          ("plate_zones (64 zones, 20 gauges)", "plate_zones_gauges.yaml")]
TRUTH = [200e9, 180e9, 150e9, 210e9]


def write_atomic(path, text):
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def bench(build_dir, config, extra=()):
    started = time.time()
    line = subprocess.run([os.path.join(build_dir, "bench", "streaming_memory_benchmark"), config,
                           *extra], check=True, capture_output=True, text=True).stdout
    fields = dict(item.split("=", 1) for item in line.split())
    print(f"  {os.path.basename(config)}: {fields['dofs']} dofs, {fields['sweeps']} sweeps, "
          f"{fields['cpu_s']} s, {fields['ns_per_dof_step']} ns per dof-step, peak "
          f"{fields['solve_peak_mb']} MB ({time.time() - started:.0f} s)", flush=True)
    return fields


def beam_config(folder, manifest, name):
    """configs/beam3d.yaml on another mesh, written into folder."""
    with open(os.path.join(ROOT, "configs", "beam3d.yaml")) as f:
        text = f.read()
    text = text.replace("manifest: beam3d/model.yaml", f"manifest: {manifest}")
    path = os.path.join(folder, name + ".yaml")
    write_atomic(path, text)
    return path


def plate_config(folder, source, name):
    """A plate config with the streaming CG and no preconditioner (its manifest made
    absolute), written into folder."""
    lines = []
    with open(os.path.join(ROOT, "configs", source)) as f:
        for line in f:
            stripped = line.strip()
            if stripped.startswith("manifest:"):
                relative = stripped.split()[1]
                line = f"  manifest: {os.path.join(ROOT, 'configs', relative)}\n"
            elif stripped.startswith("truth_manifest:"):
                relative = stripped.split()[1]
                line = f"  truth_manifest: {os.path.join(ROOT, 'configs', relative)}\n"
            elif stripped.startswith(("method:", "preconditioner:", "max_preconditioner_traces:")):
                continue
            elif stripped == "inner:":
                line = "inner:\n  method: streaming_conjugate_gradient\n  preconditioner: none\n"
            lines.append(line)
    text = "".join(lines)
    if "\ninner:" not in text:
        text += "inner:\n  method: streaming_conjugate_gradient\n  preconditioner: none\n"
    path = os.path.join(folder, name + ".yaml")
    write_atomic(path, text)
    return path


def write_figure(out, rows):
    beams = [r for r in rows if r["structure"].startswith("beam") and r["history"] == "whole"]
    plates = [r for r in rows if r["structure"].startswith("plate")]
    data = "".join(f"{r['dofs']} {r['ns_per_dof_step']} {r['solve_peak_mb']}\n" for r in beams)
    data += "\n\n" + "".join(f"{r['dofs']} {r['ns_per_dof_step']} {r['solve_peak_mb']}\n"
                             for r in plates)
    data_path = os.path.join(out, "solve_cost.dat.tmp")
    write_atomic(data_path, data)
    png = os.path.join(out, "solve_cost.png")
    script = f"""
set terminal pngcairo size 1100,450 font ',10' noenhanced
set output '{png}.tmp'
set multiplot layout 1,2 title 'One coupled solve, streaming CG (bench/streaming_memory_benchmark)'
set logscale x
set xlabel 'dofs n'
set grid
set key top left
set ylabel 'CPU per dof, step and sweep [ns]'
plot '{data_path}' index 0 using 1:2 with linespoints pt 7 title '3-D beam', \\
     '' index 1 using 1:2 with points pt 5 ps 1.5 title '2-D plates'
set logscale y
set ylabel 'peak resident memory during the solve [MB]'
plot '{data_path}' index 0 using 1:3 with linespoints pt 7 title '3-D beam', \\
     '' index 1 using 1:3 with points pt 5 ps 1.5 title '2-D plates'
unset multiplot
"""
    subprocess.run(["gnuplot"], input=script, text=True, check=True)
    os.replace(png + ".tmp", png)
    os.remove(data_path)


def main():
    if len(sys.argv) not in (3, 4) or sys.argv[3:] not in ([], ["--figure-only"]):
        sys.exit(__doc__.split("Usage: ")[1])
    build_dir, out = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    os.makedirs(out, exist_ok=True)
    if sys.argv[3:] == ["--figure-only"]:
        with open(os.path.join(out, "solve_cost.csv")) as f:
            write_figure(out, list(csv.DictReader(f)))
        return
    rows = []
    columns = ["structure", "mesh", "dofs", "steps", "traces", "history", "iterations",
               "sweeps", "cpu_s", "ns_per_dof_step", "factor_per_dof", "matrix_per_dof",
               "resident_mb", "solve_peak_mb"]
    with tempfile.TemporaryDirectory(prefix="beam3d_study_") as scratch:
        print("1. meshes (SfePy)", flush=True)
        configs = [("beam", "24 x 2 x 2", os.path.join(ROOT, "configs", "beam3d.yaml"))]
        for nx, ny, nz in MESHES:
            folder = os.path.join(scratch, f"mesh_{nx}_{ny}_{nz}")
            subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "make_beam3d_example.py"),
                            "--elements", str(nx), str(ny), str(nz), "--output", folder],
                           check=True)
            configs.append(("beam", f"{nx} x {ny} x {nz}",
                            beam_config(scratch, os.path.join(folder, "model.yaml"),
                                        f"beam_{nx}_{ny}_{nz}")))
        print("2. one coupled solve each", flush=True)
        for structure, mesh, config in configs:
            fields = bench(build_dir, config)
            rows.append(dict(fields, structure=structure, mesh=mesh, history="whole"))
        structure, mesh, config = configs[-1]
        fields = bench(build_dir, config, ["--history-bytes", str(CHECKPOINT_BYTES)])
        rows.append(dict(fields, structure=structure, mesh=mesh, history="checkpoints"))
        for name, source in PLATES:
            fields = bench(build_dir, plate_config(scratch, source, source[:-5]))
            rows.append(dict(fields, structure=name, mesh="", history="whole"))
    with open(os.path.join(out, "solve_cost.csv.tmp"), "w", newline="") as f:
        writer = csv.writer(f, lineterminator="\n")  # quotes the names with commas
        writer.writerow(columns)
        writer.writerows([r[c] for c in columns] for r in rows)
    os.replace(os.path.join(out, "solve_cost.csv.tmp"), os.path.join(out, "solve_cost.csv"))
    write_figure(out, rows)

    print("3. identify run configs/beam3d.yaml", flush=True)
    run_dir = os.path.join(out, "identify")
    shutil.rmtree(run_dir, ignore_errors=True)  # identify writes each file atomically
    started = time.time()
    subprocess.run([os.path.join(build_dir, "identify", "identify"), "run",
                    os.path.join(ROOT, "configs", "beam3d.yaml"), "--set", "output.folder=identify"],
                   check=True, cwd=out)
    seconds = time.time() - started
    with open(os.path.join(run_dir, "zones.csv")) as f:
        zones = [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]

    table = ["| structure | mesh | dofs | history | iterations | sweeps | CPU [s] | "
             "ns per dof, step and sweep | factor's nonzeros per dof (M and K's) | "
             "resident after reading [MB] | peak in the solve [MB] |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        table.append(f"| {r['structure']} | {r['mesh']} | {r['dofs']} | {r['history']} | "
                     f"{r['iterations']} | {r['sweeps']} | {float(r['cpu_s']):.3g} | "
                     f"{float(r['ns_per_dof_step']):.0f} | {float(r['factor_per_dof']):.0f} "
                     f"({float(r['matrix_per_dof']):.0f}) | {float(r['resident_mb']):.0f} | "
                     f"{float(r['solve_peak_mb']):.0f} |")
    zone_table = ["| zone | truth [GPa] | identified [GPa] | error |", "|---|---|---|---|"]
    modulus_key = next(k for k in zones[0] if k.startswith("modulus"))
    for zone, truth in zip(zones, TRUTH):
        modulus = float(zone[modulus_key])
        zone_table.append(f"| {zone['name']} | {truth / 1e9:g} | {modulus / 1e9:.3f} | "
                          f"{100 * (modulus / truth - 1):+.2f} % |")
    write_atomic(os.path.join(out, "summary.md"),
                 "# The 3-D beam on the one road (scripts/beam3d_study.sh)\n\n"
                 "One coupled solve at the nominal moduli from a zero start, streaming CG, no "
                 "preconditioner, each in its own process (bench/streaming_memory_benchmark; "
                 "`history`: the retrograde history kept whole, or in checkpoints under a "
                 f"{CHECKPOINT_BYTES >> 20} MB budget). CPU of the solve's thread; the peak is "
                 "the process's high-water mark reset before the solve, after the heap's free memory was "
                 "returned to the system (what the solve adds to what the model and data hold). A sweep "
                 "step solves with the factor of M + (theta h)^2 K and multiplies by M and K: its "
                 "work per dof follows their nonzeros per row.\n\n" +
                 "\n".join(table) + "\n\n" +
                 f"`identify run configs/beam3d.yaml` (24 x 2 x 2, SNR 20): {seconds:.0f} s\n\n" +
                 "\n".join(zone_table) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
