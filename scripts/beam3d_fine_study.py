#!/usr/bin/env python3
"""Regenerates results/beam3d/fine/: the four zones of the 3-D beam identified on its
144 x 6 x 6 mesh (21168 dofs), three meshes deep (docs/matrix_models.md section 16).

1. The 24 x 6 x 6 (3528 dofs) and 144 x 6 x 6 meshes of the beam written by
   scripts/make_beam3d_example.py (SfePy) into a temporary folder (too big to commit).
2. `identify simulate` of configs/beam3d.yaml on the fine mesh: the data (its truth
   200, 180, 150 and 210 GPa, SNR 20) as a CSV, read by every run below.
3. `identify run` on the committed 24 x 2 x 2 mesh (648 dofs) from those data: the
   homogeneous stage, then the zones. Its moduli carry that mesh's discretisation error.
4. `identify run` on the 24 x 6 x 6 mesh, every zone started from the last run's modulus
   (zone_identification.start_moduli), no homogeneous stage; then the same on the fine
   mesh from the 24 x 6 x 6 run's moduli.
Every run without the uncertainty estimate (uncertainty.samples 0) and with an hour per
minimisation. Each run's folder (summary.yaml, zones.csv, fit.csv, error_map.csv, the
figures) and
summary.md: the moduli against the truth, the evaluations, sweeps, wall time and the
process's peak resident memory of each run.

Prints progress; files are written atomically. About 75 min on one core.

Usage: /usr/bin/python3 scripts/beam3d_fine_study.py BUILD_DIR RESULTS_DIR
"""

import csv
import os
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
COMMITTED = (24, 2, 2)
MIDDLE = (24, 6, 6)
FINE = (144, 6, 6)
LIMITS = ["outer.max_time=3600", "zone_identification.max_time=3600"]
BULKY = ["error_map_dofs.csv", "error_map_spacetime.dat"]
TRUTH = [200e9, 180e9, 150e9, 210e9]


def write_atomic(path, text):
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def make_mesh(scratch, elements):
    folder = os.path.join(scratch, "mesh_{}_{}_{}".format(*elements))
    subprocess.run(["/usr/bin/python3", os.path.join(ROOT, "scripts", "make_beam3d_example.py"),
                    "--elements", *map(str, elements), "--output", folder], check=True)
    return os.path.join(folder, "model.yaml")


def read_zones(folder):
    with open(os.path.join(folder, "zones.csv")) as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    key = next(k for k in rows[0] if k.startswith("modulus"))
    return [(r["name"], float(r[key])) for r in rows]


def read_summary_value(folder, section, key):
    """The first `key:` value under the top-level `section:` of summary.yaml."""
    inside = False
    with open(os.path.join(folder, "summary.yaml")) as f:
        for line in f:
            if not line.startswith(" "):
                inside = line.split(":")[0] == section
            elif inside and line.strip().startswith(key + ":"):
                return line.split(":", 1)[1].split("#")[0].strip()
    return ""


def read_top_value(folder, key):
    """A top-level `key:` value of summary.yaml."""
    with open(os.path.join(folder, "summary.yaml")) as f:
        for line in f:
            if line.startswith(key + ":"):
                return line.split(":", 1)[1].split("#")[0].strip()
    return ""


def run_identify(build_dir, out, name, overrides):
    """identify run configs/beam3d.yaml with the overrides into out/name; returns its
    wall time [s] and its process's peak resident memory [MB]."""
    folder = os.path.join(out, name)
    shutil.rmtree(folder, ignore_errors=True)  # identify writes each file atomically
    started = time.time()
    command = [os.path.join(build_dir, "identify", "identify"), "run",
               os.path.join(ROOT, "configs", "beam3d.yaml"), "--set", f"output.folder={name}",
               "--set", "uncertainty.samples=0"]
    for override in LIMITS + overrides:
        command += ["--set", override]
    # A wrapper process whose only child is identify: its children's ru_maxrss [KiB] is
    # identify's own peak.
    wrapper = ("import resource, subprocess, sys; subprocess.run(sys.argv[1:], check=True); "
               "print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)")
    peak_kib = subprocess.run(["/usr/bin/python3", "-c", wrapper, *command], check=True, cwd=out,
                              stdout=subprocess.PIPE, text=True).stdout.split()[-1]
    # The per-dof and space-time error maps (7 MB on the fine mesh) are not kept: the
    # per-element map error_map.csv is.
    for bulky in BULKY:
        path = os.path.join(folder, bulky)
        if os.path.exists(path):
            os.remove(path)
    return time.time() - started, int(peak_kib) / 1024.0


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__.split("Usage: ")[1])
    build_dir, results = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
    out = os.path.join(results, "fine")
    os.makedirs(out, exist_ok=True)
    ladder = [("committed", COMMITTED), ("middle", MIDDLE), ("fine", FINE)]
    runs, moduli = [], {}
    with tempfile.TemporaryDirectory(prefix="beam3d_fine_") as scratch:
        print("1. meshes (SfePy)", flush=True)
        manifests = {"committed": os.path.join(ROOT, "configs", "beam3d", "model.yaml"),
                     "middle": make_mesh(scratch, MIDDLE), "fine": make_mesh(scratch, FINE)}
        print("2. the data, simulated on the fine mesh", flush=True)
        data = os.path.join(scratch, "fine_data.csv")
        subprocess.run([os.path.join(build_dir, "identify", "identify"), "simulate",
                        os.path.join(ROOT, "configs", "beam3d.yaml"), "--set",
                        f"model.manifest={manifests['fine']}", "--output", data], check=True)
        starts = []
        for step, (name, elements) in enumerate(ladder, start=3):
            print(f"{step}. the zones on the {' x '.join(map(str, elements))} mesh"
                  + (" from the last mesh's moduli" if starts else ""), flush=True)
            overrides = [f"model.manifest={manifests[name]}", "data.source=csv",
                         f"data.path={data}"]
            if starts:
                overrides.append("zone_identification.start_moduli=[" +
                                 ",".join(f"{m:.17g}" for m in starts) + "]")
            seconds, peak = run_identify(build_dir, out, name, overrides)
            moduli[name] = read_zones(os.path.join(out, name))
            starts = [m for _, m in moduli[name]]
            runs.append((name, elements, seconds, peak))

    names = [name for name, _ in ladder]
    table = ["| zone | truth [GPa] | " + " | ".join(f"{n} mesh [GPa] | error" for n in names) + " |",
             "|---|---|" + "---|---|" * len(names)]
    for z, truth in enumerate(TRUTH):
        cells = []
        for n in names:
            modulus = moduli[n][z][1]
            cells.append(f"{modulus / 1e9:.3f} | {100 * (modulus / truth - 1):+.2f} %")
        table.append(f"| {moduli[names[0]][z][0]} | {truth / 1e9:g} | " + " | ".join(cells) + " |")
    rows = ["| run | mesh | dofs | homogeneous stage's evaluations | zone evaluations | zone sweeps "
            "| wall [s] | peak resident [MB] |", "|---|---|---|---|---|---|---|---|"]
    for name, elements, seconds, peak in runs:
        folder = os.path.join(out, name)
        rows.append(f"| {name} | {' x '.join(map(str, elements))} | "
                    f"{read_summary_value(folder, 'model', 'dofs')} | "
                    f"{read_top_value(folder, 'evaluations') or '-'} | "
                    f"{read_summary_value(folder, 'zones', 'evaluations')} | "
                    f"{read_summary_value(folder, 'zones', 'sweeps')} | {seconds:.0f} | "
                    f"{peak:.0f} |")
    write_atomic(os.path.join(out, "summary.md"),
                 "# The 3-D beam's zones on 21168 dofs (scripts/beam3d_fine_study.py)\n\n"
                 "configs/beam3d.yaml's data simulated on the 144 x 6 x 6 mesh (SNR 20); its zones "
                 "identified on the committed 24 x 2 x 2 mesh (the homogeneous stage, then the "
                 "zones), then on 24 x 6 x 6 and on 144 x 6 x 6, each from the last mesh's moduli "
                 "(zone_identification.start_moduli), no uncertainty estimate. Wall time and peak "
                 "resident memory of each `identify run` process, on one core.\n\n" +
                 "\n".join(rows) + "\n\n" + "\n".join(table) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
