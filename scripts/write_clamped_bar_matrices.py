#!/usr/bin/env python3
"""Writes the paper's bar with a trusted clamp as a matrix model (docs/comparator.md).

The built-in bar of mcrewave is free-free: both end forces are measured loads and both
end displacements measured outputs. This script writes the same bar (linear elements,
consistent mass) with the clamp taken as known instead: the dof of x = 0 removed, the
measured load fL on the last dof, the measured output uL there, f0 and u0 unused. With
`model.kind: matrix` it lets `identify run` measure what trusting the clamp is worth
(issue 16), on the CSV of `identify simulate` (whose extra columns are ignored).

Usage: /usr/bin/python3 scripts/write_clamped_bar_matrices.py OUTPUT_FOLDER
       [--elements 100] [--nominal-modulus 180e9]
"""

import argparse
import os

import numpy as np

LENGTH, SECTION, DENSITY = 1.0, 1e-4, 800.0  # configs/studies.yaml [m, m^2, kg/m^3]


def write_symmetric(path, n, entries, comment):
    lower = sorted((j, i, v) for (i, j), v in entries.items() if i >= j)
    with open(path, "w") as f:
        f.write(f"%%MatrixMarket matrix coordinate real symmetric\n% {comment}\n")
        f.write(f"{n} {n} {len(lower)}\n")
        for j, i, v in lower:
            f.write(f"{i + 1} {j + 1} {v:.17g}\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("output")
    parser.add_argument("--elements", type=int, default=100)
    parser.add_argument("--nominal-modulus", type=float, default=180e9)
    args = parser.parse_args()
    os.makedirs(args.output, exist_ok=True)
    n, h, modulus = args.elements, LENGTH / args.elements, args.nominal_modulus
    mass, stiffness = {}, {}
    element_mass = DENSITY * SECTION * h / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]])
    element_stiffness = modulus * SECTION / h * np.array([[1.0, -1.0], [-1.0, 1.0]])
    for e in range(n):
        dofs = (e - 1, e)  # nodes e and e + 1; node 0 (x = 0) is clamped
        for a in range(2):
            for b in range(2):
                if dofs[a] < 0 or dofs[b] < 0:
                    continue
                key = (dofs[a], dofs[b])
                mass[key] = mass.get(key, 0.0) + element_mass[a, b]
                stiffness[key] = stiffness.get(key, 0.0) + element_stiffness[a, b]
    write_symmetric(os.path.join(args.output, "M.mtx"), n, mass, "clamped bar: mass [kg]")
    write_symmetric(os.path.join(args.output, "K.mtx"), n, stiffness,
                    f"clamped bar: stiffness [N/m] at {modulus:g} Pa")
    with open(os.path.join(args.output, "load_fL.mtx"), "w") as f:
        f.write(f"%%MatrixMarket matrix array real general\n% e_N: fL at x = L\n{n} 1\n")
        f.write("".join("1\n" if i == n - 1 else "0\n" for i in range(n)))
    with open(os.path.join(args.output, "sensor_uL.mtx"), "w") as f:
        f.write(f"%%MatrixMarket matrix coordinate real general\n% uL at x = L\n1 {n} 1\n1 {n} 1\n")
    with open(os.path.join(args.output, "model.yaml"), "w") as f:
        f.write(f"# The paper's bar, {n} elements, clamp trusted "
                "(scripts/write_clamped_bar_matrices.py)\n")
        f.write(f"mass: M.mtx\nstiffness_length: {SECTION / LENGTH}\nlength: {LENGTH}\n")
        f.write(f"zones:\n  - {{name: bar, stiffness: K.mtx, nominal_modulus: {modulus:.17g}}}\n")
        f.write("loads:\n  - {channel: fL, vector: load_fL.mtx}\n")
        f.write("sensors:\n  - {channel: uL, row: sensor_uL.mtx}\n")


if __name__ == "__main__":
    main()
