#!/usr/bin/env python3
"""Checks the plate example's matrices (configs/plate/) against SfePy's assembly.

scripts/make_plate_example.py assembles the plate with numpy alone, so that the
example can be regenerated without a finite-element package. This script assembles
the same plates with SfePy (Debian's python3-sfepy), a finite-element library a user
would use: the same mesh (bilinear quadrilaterals, nodes row by row), plane stress at
E = 200 GPa and nu = 0.3 times the thickness for each zone's stiffness, the consistent
mass rho t, both with 2 x 2 Gauss points; the clamped column's dofs removed. It then
compares M.mtx and each K_<zone>.mtx of the folders with SfePy's matrices, entry by
entry, and exits with 1 when one differs by more than 1e-12 of its largest entry.

Usage: /usr/bin/python3 scripts/check_plate_with_sfepy.py [--folder configs/plate/coarse]...
       (default: both committed folders, 24 x 6 and 48 x 12 elements)
"""

import argparse
import os
import sys

import numpy as np
import scipy.io
from sfepy.base.base import output
from sfepy.discrete import Equation, Equations, FieldVariable, Integral, Material, Problem
from sfepy.discrete.fem import FEDomain, Field, Mesh
from sfepy.mechanics.matcoefs import stiffness_from_youngpoisson
from sfepy.terms import Term

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_plate_example as plate  # noqa: E402  (the example's constants and mesh)

TOLERANCE = 1e-12


def sfepy_matrices(nx, ny):
    """M and K_<zone> of the nx x ny plate by SfePy, on all nodes (dofs 2 n, 2 n + 1)."""
    mesh = plate.Mesh(nx, ny)
    coors = np.array([[i * mesh.dx, j * mesh.dy] for j in range(ny + 1) for i in range(nx + 1)])
    cells, groups = [], []
    for j in range(ny):
        for i in range(nx):
            cells.append([nj * (nx + 1) + ni for (nj, ni) in mesh.element_nodes(i, j)])
            groups.append(1 if mesh.in_inclusion(i, j) else 0)
    sf_mesh = Mesh.from_data("plate", coors, None, [np.array(cells, dtype=np.int32)],
                             [np.array(groups, dtype=np.int32)], ["2_4"])
    domain = FEDomain("domain", sf_mesh)
    omega = domain.create_region("Omega", "all")
    field = Field.from_args("u", np.float64, "vector", omega, approx_order=1)
    u = FieldVariable("u", "unknown", field)
    v = FieldVariable("v", "test", field, primary_var_name="u")
    solid = Material("solid",
                     D=plate.THICKNESS * stiffness_from_youngpoisson(2, plate.NOMINAL_MODULUS,
                                                                     plate.POISSON,
                                                                     plane="stress"),
                     rho=plate.DENSITY * plate.THICKNESS)
    integral = Integral("i", order=2)  # 2 x 2 Gauss points on quadrilaterals

    def assemble(expression, region):
        term = Term.new(expression, integral, region, solid=solid, v=v, u=u)
        equations = Equations([Equation("e", term)])
        problem = Problem("plate", equations=equations, active_only=False)
        problem.time_update()
        problem.update_materials()
        return equations.evaluate(mode="weak", dw_mode="matrix",
                                  asm_obj=equations.create_matrix_graph()).toarray()

    matrices = {"M": assemble("dw_dot(solid.rho, v, u)", omega)}
    for group, zone in ((0, "matrix"), (1, "inclusion")):
        region = domain.create_region(zone, f"cells of group {group}")
        matrices[f"K_{zone}"] = assemble("dw_lin_elastic(solid.D, v, u)", region)
    # Our dof d of node (j, i) is SfePy's 2 n (+ 1), n = j (nx + 1) + i.
    order = []
    for j in range(ny + 1):
        for i in range(1, nx + 1):
            n = j * (nx + 1) + i
            order += [2 * n, 2 * n + 1]
    assert len(order) == mesh.dofs
    return {name: a[np.ix_(order, order)] for name, a in matrices.items()}


def check(folder):
    with open(os.path.join(folder, "nodes.csv")) as f:
        rows = f.read().split("\n")[1:]
    xs = sorted({float(r.split(",")[1]) for r in rows if r})
    ys = sorted({float(r.split(",")[2]) for r in rows if r})
    nx, ny = len(xs) - 1, len(ys) - 1
    ok = True
    for name, expected in sfepy_matrices(nx, ny).items():
        committed = scipy.io.mmread(os.path.join(folder, name + ".mtx")).toarray()
        difference = np.abs(committed - expected).max() / np.abs(expected).max()
        print(f"{folder}: {name}.mtx ({nx} x {ny} elements, {committed.shape[0]} dofs) against "
              f"SfePy: max difference {difference:.2e} of the largest entry")
        ok = ok and difference <= TOLERANCE
    return ok


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
    parser.add_argument("--folder", action="append",
                        help="a folder of make_plate_example.py (repeatable)")
    args = parser.parse_args()
    output.set_output(quiet=True)
    folders = args.folder or [os.path.join(root, "configs", "plate", "coarse"),
                              os.path.join(root, "configs", "plate", "fine")]
    sys.exit(0 if all([check(folder) for folder in folders]) else 1)
