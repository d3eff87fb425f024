#!/usr/bin/env python3
"""Writes the many-zone plate example of mcrewave (configs/plate_zones/) with SfePy.

A cantilever plate in plane stress, 0.4 x 0.1 x 0.01 m, clamped on its left edge x = 0 and
hit by an axial impact on its free edge x = L, assembled by SfePy (Debian's
python3-sfepy): bilinear quadrilaterals, 2 x 2 Gauss points, plane stress at
E = 200 GPa and nu = 0.3 times the thickness, consistent mass rho t; the clamped dofs
eliminated. Two meshes of the same plate are written:

    configs/plate_zones/model/  the identification's model, 48 x 12 elements (1248 dofs):
                                M, one zone 'plate' (K.mtx) and the element blocks with
                                their centroids, so that the config chooses the zones
                                (model.zoning: grid or per_element; docs/matrix_models.md
                                section 4). Three manifests: full-field data (ux and uy
                                at every free node: one observation matrix and a file of
                                channel names), ten point sensors, and the candidates of
                                `identify sensors` (the full field and a strain gauge on
                                every horizontal element edge).
    configs/plate_zones/truth/  the truths, 96 x 24 elements (4800 dofs): each inclusion
                                follows the finer elements (those whose centroid lies in
                                it), one manifest per truth with the model's channels
                                (the model's nodes are nodes of this mesh).

The truths (modulus relative to 200 GPa):
    soft_inclusion   a circle of 0.7 E, centre (0.26, 0.055) m, radius 0.022 m
    two_inclusions   a soft circle of 0.7 E at (0.12, 0.04) m, r 0.02 m, and a stiff one
                     of 1.3 E at (0.29, 0.065) m, r 0.018 m
    soft_band        a band of 0.5 E, 1/120 m wide, from the lower edge to y = 0.0625 m
                     at x in [0.2125, 0.2208] m: a crack-like defect

Channels: F, the impact's history [N] (a unit +x traction resultant on the edge x = L);
ux_<i>_<j> and uy_<i>_<j>, the displacements of the model's node (i, j) (i = 1..48
along x, j = 0..12 along y); exx_<i>_<j>, the strain between the model's nodes (i, j) and
(i + 1, j) (i = 0..47); the point sensors of POINT_SENSORS.

Checks before writing: each element's stiffness annihilates the rigid-body modes, the
mass sums to rho t L H, and one element's blocks match the textbook Q4 matrices of
scripts/make_plate_example.py (an independent assembly) to 1e-12.

Usage: /usr/bin/python3 scripts/make_plate_zones_example.py [--output configs/plate_zones]
           [--model-elements NX NY]
       --model-elements: another model mesh (default 48 12, the committed files), its
           truths REFINE times finer, written to --output (docs/matrix_models.md section 14
           refits the soft inclusion on 96 x 24).
"""

import argparse
import os
import sys

import numpy as np
import scipy.sparse
from sfepy.base.base import output
from sfepy.discrete import Integral, Material
from sfepy.mechanics.matcoefs import stiffness_from_youngpoisson

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_plate_example as textbook  # noqa: E402  (the independent Q4 element)

from plate_zones_geometry import (DENSITY, LENGTH, HEIGHT, MODEL_ELEMENTS,  # noqa: E402
                                  NOMINAL_MODULUS, POINT_SENSORS, POISSON, REFINE,
                                  THICKNESS, TRUTHS, Grid)
from sfepy_vector_field import VectorField  # noqa: E402


class Assembly(VectorField):
    """SfePy's field, terms and assembled matrices on a Grid."""

    def __init__(self, grid, groups):
        self.grid = grid
        coors = np.array([[i * grid.dx, j * grid.dy] for j in range(grid.ny + 1)
                          for i in range(grid.nx + 1)])
        cells = np.array([[grid.node(i, j), grid.node(i + 1, j), grid.node(i + 1, j + 1),
                           grid.node(i, j + 1)] for j in range(grid.ny) for i in range(grid.nx)],
                         dtype=np.int32)
        super().__init__("plate", coors, cells, "2_4", groups)
        self.solid = Material("solid", D=THICKNESS * stiffness_from_youngpoisson(
            2, NOMINAL_MODULUS, POISSON, plane="stress"), rho=DENSITY * THICKNESS)
        self.integral = Integral("i", order=2)  # 2 x 2 Gauss points on quadrilaterals
        # Our dof of SfePy's dof 2 n + c (-1: clamped).
        self.ours = np.full(2 * len(coors), -1)
        for j in range(grid.ny + 1):
            for i in range(grid.nx + 1):
                for c in range(2):
                    self.ours[2 * grid.node(i, j) + c] = grid.dof(i, j, c)

    def element_blocks(self, expression, region):
        """Per cell of `region`: the cell and its 8 x 8 block, SfePy's element dofs in
        field order (ux of the four nodes, then their uy)."""
        return self.element_matrices(expression, self.integral, region, solid=self.solid)

    def element_dofs(self, cell):
        """Our dofs of a cell's 8 element dofs in SfePy's order (-1: clamped)."""
        nodes = self.field.econn[cell]
        return [self.ours[2 * n + c] for c in range(2) for n in nodes]

    def global_matrix(self, blocks):
        """The sum of `blocks` on our free dofs, as a sparse matrix."""
        rows, cols, values = [], [], []
        for cell, block in blocks:
            dofs = np.array(self.element_dofs(cell))
            kept = np.nonzero(dofs >= 0)[0]
            for a in kept:
                for b in kept:
                    rows.append(dofs[a])
                    cols.append(dofs[b])
                    values.append(block[a, b])
        n = self.grid.dofs
        return scipy.sparse.coo_matrix((values, (rows, cols)), shape=(n, n)).tocsr()

    def region_of(self, name, group):
        return self.domain.create_region(name, f"cells of group {group}")


def check_blocks(assembly, stiffness_blocks, mass_blocks):
    """Rigid-body modes in every stiffness block's kernel, the mass rho t L H, and one
    element against the textbook Q4 of make_plate_example.py."""
    grid = assembly.grid
    for cell, block in stiffness_blocks:
        x = assembly.domain.mesh.coors[assembly.field.econn[cell]]
        for mode in (np.r_[np.ones(4), np.zeros(4)], np.r_[np.zeros(4), np.ones(4)],
                     np.r_[-x[:, 1], x[:, 0]]):
            assert np.abs(block @ mode).max() < 1e-12 * np.abs(block).max(), cell
    total = sum(block.sum() for _, block in mass_blocks) / 2  # two components
    assert abs(total / (DENSITY * THICKNESS * LENGTH * HEIGHT) - 1) < 1e-12, total
    k_textbook, m_textbook = textbook.q4_matrices(grid.dx, grid.dy, NOMINAL_MODULUS)
    # The textbook's dofs (ux, uy) per node, nodes counter-clockwise from the lower left:
    # SfePy's field order is the same nodes, ux first.
    order = [0, 2, 4, 6, 1, 3, 5, 7]
    k_sfepy = dict(stiffness_blocks)[0]
    m_sfepy = dict(mass_blocks)[0]
    for ours, theirs in ((k_sfepy, k_textbook[np.ix_(order, order)]),
                         (m_sfepy, m_textbook[np.ix_(order, order)])):
        assert np.abs(ours - theirs).max() <= 1e-12 * np.abs(theirs).max()


def write_symmetric(path, matrix, digits, comment):
    lower = scipy.sparse.tril(matrix).tocoo()
    order = np.lexsort((lower.row, lower.col))
    with open(path + ".tmp", "w") as f:
        f.write("%%MatrixMarket matrix coordinate real symmetric\n")
        f.write("% " + comment + "\n")
        f.write(f"{matrix.shape[0]} {matrix.shape[1]} {lower.nnz}\n")
        for k in order:
            f.write(f"{lower.row[k] + 1} {lower.col[k] + 1} {lower.data[k]:.{digits}g}\n")
    os.replace(path + ".tmp", path)


def write_rows(path, rows, n, comment):
    """rows: a list of {dof: coefficient}, one per channel, as an S x n matrix."""
    entries = [(r, d, v) for r, row in enumerate(rows) for d, v in sorted(row.items())]
    with open(path + ".tmp", "w") as f:
        f.write("%%MatrixMarket matrix coordinate real general\n")
        f.write("% " + comment + "\n")
        f.write(f"{len(rows)} {n} {len(entries)}\n")
        for r, d, v in entries:
            f.write(f"{r + 1} {d + 1} {v:.17g}\n")
    os.replace(path + ".tmp", path)


def write_text(path, text):
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def write_channels(folder, grid):
    """The load, the full-field observation matrix and its channel names, and the point
    sensors' rows, on `grid` (the model's nodes are nodes of every refinement)."""
    model = Grid(*MODEL_ELEMENTS)
    scale = grid.nx // model.nx
    load = np.zeros(grid.dofs)
    for j in range(grid.ny):
        for nj in (j, j + 1):
            load[grid.dof(grid.nx, nj, 0)] += 0.5 / grid.ny
    textbook.write_vector(os.path.join(folder, "load_Fx.mtx"), load,
                 "unit +x traction resultant on the edge x = L; history: channel F [N]")
    names, rows = [], []
    for j in range(model.ny + 1):
        for i in range(1, model.nx + 1):
            for c, axis in enumerate("xy"):
                names.append(f"u{axis}_{i}_{j}")
                rows.append({grid.dof(i * scale, j * scale, c): 1.0})
    write_rows(os.path.join(folder, "H_full_field.mtx"), rows, grid.dofs,
               "ux and uy of every free node of the 48 x 12 model [m]")
    write_text(os.path.join(folder, "full_field_channels.txt"),
               "# the rows of H_full_field.mtx: u<axis>_<i>_<j>, the model's node (i, j)\n" +
               "\n".join(names) + "\n")
    # A strain gauge on every horizontal edge of the model's elements: exx between the
    # model's nodes (i, j) and (i + 1, j), (ux_b - ux_a) / dx (ux = 0 on the clamped edge).
    names, rows = [], []
    dx = LENGTH / model.nx
    for j in range(model.ny + 1):
        for i in range(model.nx):
            names.append(f"exx_{i}_{j}")
            row = {grid.dof((i + 1) * scale, j * scale, 0): 1.0 / dx}
            if i > 0:
                row[grid.dof(i * scale, j * scale, 0)] = -1.0 / dx
            rows.append(row)
    write_rows(os.path.join(folder, "H_strain_field.mtx"), rows, grid.dofs,
               "exx on every horizontal edge of the 48 x 12 model's elements [-]")
    write_text(os.path.join(folder, "strain_field_channels.txt"),
               "# the rows of H_strain_field.mtx: exx_<i>_<j>, the strain between the model's "
               "nodes (i, j) and (i + 1, j)\n" + "\n".join(names) + "\n")
    for sensor in POINT_SENSORS:
        channel, kind = sensor[0], sensor[1]
        if kind in ("ux", "uy"):
            i, j = grid.node_at(sensor[2], sensor[3])
            row = {grid.dof(i, j, 0 if kind == "ux" else 1): 1.0}
        else:
            ia, ja = grid.node_at(sensor[2], sensor[3])
            ib, jb = grid.node_at(sensor[4], sensor[3])
            row = {grid.dof(ib, jb, 0): 1.0 / (sensor[4] - sensor[2]),
                   grid.dof(ia, ja, 0): -1.0 / (sensor[4] - sensor[2])}
        write_rows(os.path.join(folder, f"sensor_{channel}.mtx"), [row], grid.dofs,
                   f"sensor {channel} ({kind})")


def manifest_head(title, grid):
    return (f"# {title}: cantilever plate {LENGTH} x {HEIGHT} x {THICKNESS} m, Q4 plane stress "
            f"{grid.nx} x {grid.ny} elements, {grid.dofs} dofs, axial impact\n"
            "# (scripts/make_plate_zones_example.py, assembled by SfePy; configs/plate_zones/README.md)\n"
            f"mass: M.mtx\nstiffness_length: {THICKNESS}\nlength: {LENGTH}\n")


POINT_SENSORS_YAML = "".join(
    f"  - {{channel: {s[0]}, row: sensor_{s[0]}.mtx{', kind: strain' if s[1] == 'exx' else ''}}}\n"
    for s in POINT_SENSORS)
FULL_FIELD_YAML = ("sensors_matrix: {matrix: H_full_field.mtx, channels: full_field_channels.txt, "
                   "kind: displacement}\n")
# The full field and the strain gauges on every horizontal element edge: the candidates of
# `identify sensors` (docs/matrix_models.md section 15).
CANDIDATES_YAML = ("sensors_matrix:\n"
                   "  - {matrix: H_full_field.mtx, channels: full_field_channels.txt, "
                   "kind: displacement}\n"
                   "  - {matrix: H_strain_field.mtx, channels: strain_field_channels.txt, "
                   "kind: strain}\n")


def write_model(folder):
    grid = Grid(*MODEL_ELEMENTS)
    os.makedirs(folder, exist_ok=True)
    assembly = Assembly(grid, [0] * (grid.nx * grid.ny))
    stiffness = assembly.element_blocks("dw_lin_elastic(solid.D, v, u)", assembly.omega)
    mass = assembly.element_blocks("dw_dot(solid.rho, v, u)", assembly.omega)
    check_blocks(assembly, stiffness, mass)
    write_symmetric(os.path.join(folder, "M.mtx"), assembly.global_matrix(mass), 17,
                    f"consistent mass [kg], Q4 plane stress {grid.nx} x {grid.ny} (SfePy)")
    write_symmetric(os.path.join(folder, "K.mtx"), assembly.global_matrix(stiffness), 17,
                    f"stiffness [N/m] at E = {NOMINAL_MODULUS:g} Pa (SfePy)")
    write_channels(folder, grid)
    dofs_lines, block_lines, position_lines = [], [], []
    for cell, block in sorted(stiffness):
        dofs = np.array(assembly.element_dofs(cell))
        kept = np.nonzero(dofs >= 0)[0]
        dofs_lines.append("plate," + ",".join(str(d) for d in dofs[kept]))
        block_lines.append(",".join(f"{v:.17g}" for v in block[np.ix_(kept, kept)].ravel()))
        x, y = grid.centroid(cell)
        position_lines.append(f"{x:.17g},{y:.17g}")
    write_text(os.path.join(folder, "element_dofs.csv"),
               "# zone, then the element's dofs (0-based); element e = j 48 + i\n" +
               "\n".join(dofs_lines) + "\n")
    write_text(os.path.join(folder, "element_stiffness.csv"),
               f"# the element's block of K [N/m] at E = {NOMINAL_MODULUS:g} Pa, row by row\n" +
               "\n".join(block_lines) + "\n")
    write_text(os.path.join(folder, "element_positions.csv"),
               "# the element's centroid x, y [m]\n" + "\n".join(position_lines) + "\n")
    common = (f"zones:\n  - {{name: plate, stiffness: K.mtx, "
              f"nominal_modulus: {NOMINAL_MODULUS:.17g}}}\n"
              "loads:\n  - {channel: F, vector: load_Fx.mtx}\n")
    elements = ("elements: {dofs: element_dofs.csv, stiffness: element_stiffness.csv, "
                "positions: element_positions.csv}\n")
    write_text(os.path.join(folder, "full_field.yaml"),
               manifest_head("The model, full-field data (ux, uy at every free node)", grid) +
               common + FULL_FIELD_YAML + elements)
    write_text(os.path.join(folder, "candidates.yaml"),
               manifest_head("The model, candidate sensors (ux, uy at every free node; exx on "
                             "every horizontal element edge)", grid) + common +
               CANDIDATES_YAML + elements)
    write_text(os.path.join(folder, "points.yaml"),
               manifest_head("The model, ten point sensors", grid) + common + "sensors:\n" +
               POINT_SENSORS_YAML + elements)
    print(f"{folder}: {grid.nx} x {grid.ny} elements, {grid.dofs} dofs")


def write_truths(folder):
    grid = Grid(MODEL_ELEMENTS[0] * REFINE, MODEL_ELEMENTS[1] * REFINE)
    os.makedirs(folder, exist_ok=True)
    cells = grid.nx * grid.ny
    assembly = Assembly(grid, [0] * cells)
    stiffness = dict(assembly.element_blocks("dw_lin_elastic(solid.D, v, u)", assembly.omega))
    mass = assembly.element_blocks("dw_dot(solid.rho, v, u)", assembly.omega)
    check_blocks(assembly, list(stiffness.items()), mass)
    write_symmetric(os.path.join(folder, "M.mtx"), assembly.global_matrix(mass), 12,
                    f"consistent mass [kg], Q4 plane stress {grid.nx} x {grid.ny} (SfePy)")
    write_channels(folder, grid)
    for truth, inclusions in TRUTHS.items():
        zone_of = np.zeros(cells, dtype=int)  # 0: the matrix
        for cell in range(cells):
            x, y = grid.centroid(cell)
            for z, (_, _, inside) in enumerate(inclusions):
                if inside(x, y):
                    zone_of[cell] = z + 1
        names = ["matrix"] + [name for name, _, _ in inclusions]
        yaml = manifest_head(f"The truth '{truth}'", grid) + "zones:\n"
        counts = []
        for z, name in enumerate(names):
            blocks = [(cell, stiffness[cell]) for cell in range(cells) if zone_of[cell] == z]
            counts.append(len(blocks))
            write_symmetric(os.path.join(folder, f"K_{truth}_{name}.mtx"),
                            assembly.global_matrix(blocks), 12,
                            f"stiffness of zone {name} of {truth} [N/m] at E = "
                            f"{NOMINAL_MODULUS:g} Pa (SfePy)")
            yaml += (f"  - {{name: {name}, stiffness: K_{truth}_{name}.mtx, "
                     f"nominal_modulus: {NOMINAL_MODULUS:.17g}}}\n")
        moduli = [1.0] + [modulus for _, modulus, _ in inclusions]
        yaml += ("# data.truth_moduli: [" +
                 ", ".join(f"{m * NOMINAL_MODULUS:g}" for m in moduli) + "]\n")
        yaml += ("loads:\n  - {channel: F, vector: load_Fx.mtx}\n" + CANDIDATES_YAML +
                 "sensors:\n" + POINT_SENSORS_YAML)
        write_text(os.path.join(folder, f"{truth}.yaml"), yaml)
        print(f"{folder}/{truth}.yaml: {grid.nx} x {grid.ny} elements, {grid.dofs} dofs, "
              f"elements per zone {dict(zip(names, counts))}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--output", default=os.path.join(os.path.dirname(__file__), "..",
                                                         "configs", "plate_zones"))
    parser.add_argument("--model-elements", nargs=2, type=int, default=list(MODEL_ELEMENTS),
                        metavar=("NX", "NY"), help="the model's mesh (default 48 12)")
    args = parser.parse_args()
    if min(args.model_elements) < 1 or any(n % m for n, m in zip(args.model_elements, (48, 12))):
        parser.error("--model-elements must be multiples of 48 and 12 (the point sensors sit "
                     "on nodes of the committed 48 x 12 mesh)")
    MODEL_ELEMENTS = tuple(args.model_elements)
    output.set_output(quiet=True)
    write_model(os.path.join(args.output, "model"))
    write_truths(os.path.join(args.output, "truth"))
