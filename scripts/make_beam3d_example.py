#!/usr/bin/env python3
"""Writes the 3-D example of mcrewave (configs/beam3d/) with SfePy.

A steel cantilever beam, 0.72 x 0.03 x 0.03 m (x, y, z), clamped on its face x = 0 and
hit on its free face x = L by an oblique impact: a uniform traction whose resultant is
the CSV channel F [N] times the unit direction (1, 0.5, 0.25) / |.|, so that the beam
answers with axial waves and bending about both axes. Assembled by SfePy (Debian's
python3-sfepy): trilinear hexahedra, 2 x 2 x 2 Gauss points, isotropic elasticity at
E = 200 GPa and nu = 0.3, consistent mass; the clamped dofs eliminated.

Four zones of equal length along the beam, s1 (at the clamp) to s4 (at the tip), each
with its stiffness K_s<k>.mtx at 200 GPa, and the element blocks (dofs, 24 x 24 blocks
less the clamped dofs, centroids x, y, z), so that a config may also regroup the
elements (model.zoning: grid or per_element; docs/matrix_models.md section 4).

Sensors (nodes of every mesh the script accepts, so that meshes of one beam share their
channels): ux_tip, uy_tip, uz_tip at the centre of the free face; strain gauges e_xx of
L/12 on the upper face z = H along its centre line, one at the middle of each zone
(exx_top_1 to exx_top_4), and on the side face y = 0 at mid-height (exx_side_2,
exx_side_4).

    --elements NX NY NZ   the mesh (NX a multiple of 24, NY and NZ even); the committed
                          model is 24 x 2 x 2 (648 dofs); 144 x 6 x 6 gives 21168 dofs
                          (scripts/beam3d_study.sh writes it and others outside the tree)

Checks before writing: each element's stiffness annihilates the six rigid-body modes,
the mass sums to rho L B H, and one element's blocks equal an independent trilinear
brick (numpy, 2 x 2 x 2 Gauss points) to 1e-12.

Usage: /usr/bin/python3 scripts/make_beam3d_example.py [--output configs/beam3d]
           [--elements 24 2 2]
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
from sfepy_vector_field import VectorField  # noqa: E402

LENGTH = 0.72  # L [m], along x
WIDTH = 0.03  # B [m], along y
HEIGHT = 0.03  # H [m], along z
DENSITY = 7800.0  # rho [kg/m^3]
POISSON = 0.3
NOMINAL_MODULUS = 200e9  # [Pa]
ZONES = 4  # of equal length along x
LOAD_DIRECTION = np.array([1.0, 0.5, 0.25]) / np.linalg.norm([1.0, 0.5, 0.25])
GAUGE = LENGTH / 12  # gauge length [m]
# (channel, kind, x [m], y, z[, x2]): u<axis> the node's displacement; exx the gauge
# (u_x(x2, y, z) - u_x(x, y, z)) / (x2 - x).
SENSORS = [("ux_tip", "ux", LENGTH, WIDTH / 2, HEIGHT / 2),
           ("uy_tip", "uy", LENGTH, WIDTH / 2, HEIGHT / 2),
           ("uz_tip", "uz", LENGTH, WIDTH / 2, HEIGHT / 2)]
for k in range(ZONES):
    middle = (k + 0.5) * LENGTH / ZONES
    SENSORS.append((f"exx_top_{k + 1}", "exx", middle - GAUGE / 2, WIDTH / 2, HEIGHT,
                    middle + GAUGE / 2))
for k in (1, 3):
    middle = (k + 0.5) * LENGTH / ZONES
    SENSORS.append((f"exx_side_{k + 1}", "exx", middle - GAUGE / 2, 0.0, HEIGHT / 2,
                    middle + GAUGE / 2))


class Grid:
    """An nx x ny x nz mesh of equal bricks; node (i, j, k) at (i dx, j dy, k dz) is
    node (k (ny + 1) + j) (nx + 1) + i; the clamped face i = 0 eliminated, and the free
    node (i, j, k) has the dofs 3 ((i - 1) (ny + 1) (nz + 1) + k (ny + 1) + j) + c,
    c = 0, 1, 2 for x, y, z (cross-section by cross-section from the clamp)."""

    def __init__(self, nx, ny, nz):
        self.nx, self.ny, self.nz = nx, ny, nz
        self.dx, self.dy, self.dz = LENGTH / nx, WIDTH / ny, HEIGHT / nz
        self.dofs = 3 * nx * (ny + 1) * (nz + 1)

    def node(self, i, j, k):
        return (k * (self.ny + 1) + j) * (self.nx + 1) + i

    def node_at(self, x, y, z):
        i, j, k = round(x / self.dx), round(y / self.dy), round(z / self.dz)
        assert max(abs(i * self.dx - x), abs(j * self.dy - y), abs(k * self.dz - z)) < 1e-9
        return i, j, k

    def dof(self, i, j, k, c):
        if i == 0:
            return -1
        return 3 * ((i - 1) * (self.ny + 1) * (self.nz + 1) + k * (self.ny + 1) + j) + c

    def cells(self):
        """(i, j, k) of each cell, i fastest; SfePy's hexahedron numbering: the lower
        face counter-clockwise from (0, 0, 0), then the upper face."""
        return [(i, j, k) for k in range(self.nz) for j in range(self.ny) for i in range(self.nx)]

    def cell_nodes(self, i, j, k):
        return [self.node(i + a, j + b, k + c) for c in (0, 1)
                for a, b in ((0, 0), (1, 0), (1, 1), (0, 1))]

    def zone(self, i):
        return i * ZONES // self.nx


def brick_matrices(dx, dy, dz, modulus):
    """An independent trilinear brick: stiffness and consistent mass by 2 x 2 x 2 Gauss
    points, nodes as Grid.cell_nodes, dofs (ux, uy, uz) per node."""
    lam = modulus * POISSON / ((1 + POISSON) * (1 - 2 * POISSON))
    mu = modulus / (2 * (1 + POISSON))
    d = np.zeros((6, 6))
    d[:3, :3] = lam
    d[np.arange(3), np.arange(3)] += 2 * mu
    d[np.arange(3, 6), np.arange(3, 6)] = mu
    signs = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                      [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)
    half = np.array([dx, dy, dz]) / 2
    k = np.zeros((24, 24))
    m = np.zeros((24, 24))
    g = 1 / np.sqrt(3)
    for p in np.array(np.meshgrid([-g, g], [-g, g], [-g, g])).reshape(3, -1).T:
        shape = np.prod(1 + signs * p, axis=1) / 8
        grad = np.zeros((8, 3))
        for a in range(3):
            others = [b for b in range(3) if b != a]
            grad[:, a] = signs[:, a] * np.prod(1 + signs[:, others] * p[others], axis=1) / 8
        grad /= half
        b = np.zeros((6, 24))
        for n in range(8):
            gx, gy, gz = grad[n]
            b[0, 3 * n], b[1, 3 * n + 1], b[2, 3 * n + 2] = gx, gy, gz
            b[3, 3 * n + 1], b[3, 3 * n + 2] = gz, gy  # gamma_yz
            b[4, 3 * n], b[4, 3 * n + 2] = gz, gx  # gamma_xz
            b[5, 3 * n], b[5, 3 * n + 1] = gy, gx  # gamma_xy
        jacobian = np.prod(half)
        k += b.T @ d @ b * jacobian
        n_matrix = np.kron(shape[None, :], np.eye(3)).reshape(3, 24)
        m += DENSITY * n_matrix.T @ n_matrix * jacobian
    return k, m


class Assembly(VectorField):
    """SfePy's field, terms and element blocks on a Grid."""

    def __init__(self, grid):
        self.grid = grid
        coors = np.array([[i * grid.dx, j * grid.dy, k * grid.dz]
                          for k in range(grid.nz + 1) for j in range(grid.ny + 1)
                          for i in range(grid.nx + 1)])
        cells = np.array([grid.cell_nodes(*c) for c in grid.cells()], dtype=np.int32)
        super().__init__("beam", coors, cells, "3_8")
        self.solid = Material("solid", D=stiffness_from_youngpoisson(3, NOMINAL_MODULUS, POISSON),
                              rho=DENSITY)
        self.integral = Integral("i", order=2)  # 2 x 2 x 2 Gauss points on hexahedra
        self.ours = np.full(3 * len(coors), -1)  # our dof of SfePy's dof 3 n + c
        for k in range(grid.nz + 1):
            for j in range(grid.ny + 1):
                for i in range(grid.nx + 1):
                    for c in range(3):
                        self.ours[3 * grid.node(i, j, k) + c] = grid.dof(i, j, k, c)
        # Each cell's 24 element dofs in SfePy's field order (ux of the eight nodes,
        # then uy, then uz), as our dofs (-1: clamped).
        self.element_dofs = np.array([[self.ours[3 * n + c] for c in range(3) for n in nodes]
                                      for nodes in cells])

    def blocks(self, expression):
        """Every cell's 24 x 24 block, in cell order."""
        blocks = self.element_matrices(expression, self.integral, self.omega, solid=self.solid)
        assert [cell for cell, _ in blocks] == list(range(len(blocks)))
        return np.array([block for _, block in blocks])

    def global_matrix(self, blocks, cells):
        """The sum of the blocks of `cells` on our free dofs."""
        dofs = self.element_dofs[cells]
        rows = np.repeat(dofs, 24, axis=1).ravel()
        cols = np.tile(dofs, (1, 24)).ravel()
        values = blocks[cells].reshape(len(cells), -1).ravel()
        kept = (rows >= 0) & (cols >= 0)
        n = self.grid.dofs
        return scipy.sparse.coo_matrix((values[kept], (rows[kept], cols[kept])),
                                       shape=(n, n)).tocsr()


def check_blocks(assembly, stiffness, mass):
    grid = assembly.grid
    coors = assembly.domain.mesh.coors
    for cell in range(len(stiffness)):
        x = coors[assembly.field.econn[cell]]
        one, zero = np.ones(8), np.zeros(8)
        modes = [np.r_[one, zero, zero], np.r_[zero, one, zero], np.r_[zero, zero, one],
                 np.r_[-x[:, 1], x[:, 0], zero], np.r_[-x[:, 2], zero, x[:, 0]],
                 np.r_[zero, -x[:, 2], x[:, 1]]]
        for mode in modes:
            assert np.abs(stiffness[cell] @ mode).max() < 1e-10 * np.abs(stiffness[cell]).max()
    total = mass.sum() / 3  # three components
    assert abs(total / (DENSITY * LENGTH * WIDTH * HEIGHT) - 1) < 1e-12, total
    k_brick, m_brick = brick_matrices(grid.dx, grid.dy, grid.dz, NOMINAL_MODULUS)
    order = [3 * n + c for c in range(3) for n in range(8)]  # SfePy's field order
    for ours, theirs in ((stiffness[0], k_brick[np.ix_(order, order)]),
                         (mass[0], m_brick[np.ix_(order, order)])):
        assert np.abs(ours - theirs).max() <= 1e-12 * np.abs(theirs).max()


def write_text(path, text):
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def write_symmetric(path, matrix, comment):
    lower = scipy.sparse.tril(matrix).tocoo()
    order = np.lexsort((lower.row, lower.col))
    lines = [f"{r + 1} {c + 1} {v:.17g}"
             for r, c, v in zip(lower.row[order], lower.col[order], lower.data[order])]
    write_text(path, "%%MatrixMarket matrix coordinate real symmetric\n% " + comment + "\n" +
               f"{matrix.shape[0]} {matrix.shape[1]} {lower.nnz}\n" + "\n".join(lines) + "\n")


def write_rows(path, rows, n, comment):
    """rows: a list of {dof: coefficient}, one per channel, as an S x n matrix."""
    entries = [(r, d, v) for r, row in enumerate(rows) for d, v in sorted(row.items())]
    write_text(path, "%%MatrixMarket matrix coordinate real general\n% " + comment + "\n" +
               f"{len(rows)} {n} {len(entries)}\n" +
               "".join(f"{r + 1} {d + 1} {v:.17g}\n" for r, d, v in entries))


def write_channels(folder, grid):
    """The load vector and the sensors' observation matrices with their channel names."""
    load = np.zeros(grid.dofs)
    face = 1.0 / (grid.ny * grid.nz)  # each face quad's share of the resultant
    for j in range(grid.ny):
        for k in range(grid.nz):
            for b, c in ((0, 0), (1, 0), (1, 1), (0, 1)):
                for axis in range(3):
                    load[grid.dof(grid.nx, j + b, k + c, axis)] += face / 4 * LOAD_DIRECTION[axis]
    assert abs(load.sum() - LOAD_DIRECTION.sum()) < 1e-12
    write_text(os.path.join(folder, "load_F.mtx"),
               "%%MatrixMarket matrix array real general\n"
               "% a uniform traction on the face x = L, unit resultant along (1, 0.5, 0.25) / "
               "|.|; history: channel F [N]\n" + f"{grid.dofs} 1\n" +
               "".join(f"{v:.17g}\n" for v in load))
    kinds = {"displacement": [], "strain": []}
    for sensor in SENSORS:
        channel, kind = sensor[0], sensor[1]
        if kind.startswith("u"):
            i, j, k = grid.node_at(*sensor[2:5])
            kinds["displacement"].append((channel, {grid.dof(i, j, k, "xyz".index(kind[1])): 1.0}))
        else:
            ia, ja, ka = grid.node_at(*sensor[2:5])
            ib, jb, kb = grid.node_at(sensor[5], *sensor[3:5])
            span = sensor[5] - sensor[2]
            kinds["strain"].append((channel, {grid.dof(ib, jb, kb, 0): 1.0 / span,
                                              grid.dof(ia, ja, ka, 0): -1.0 / span}))
    for kind, sensors in kinds.items():
        write_rows(os.path.join(folder, f"H_{kind}.mtx"), [row for _, row in sensors],
                   grid.dofs, f"the {kind} sensors of {kind}_channels.txt, one row each")
        write_text(os.path.join(folder, f"{kind}_channels.txt"),
                   f"# the rows of H_{kind}.mtx\n" + "\n".join(c for c, _ in sensors) + "\n")


def write_model(folder, grid):
    os.makedirs(folder, exist_ok=True)
    assembly = Assembly(grid)
    stiffness = assembly.blocks("dw_lin_elastic(solid.D, v, u)")
    mass = assembly.blocks("dw_dot(solid.rho, v, u)")
    check_blocks(assembly, stiffness, mass)
    cells = grid.cells()
    all_cells = np.arange(len(cells))
    shape = f"{grid.nx} x {grid.ny} x {grid.nz} hexahedra (SfePy)"
    write_symmetric(os.path.join(folder, "M.mtx"), assembly.global_matrix(mass, all_cells),
                    f"consistent mass [kg], {shape}")
    zone_of = np.array([grid.zone(i) for i, _, _ in cells])
    zones_yaml = ""
    for z in range(ZONES):
        name = f"s{z + 1}"
        write_symmetric(os.path.join(folder, f"K_{name}.mtx"),
                        assembly.global_matrix(stiffness, np.nonzero(zone_of == z)[0]),
                        f"stiffness of zone {name} [N/m] at E = {NOMINAL_MODULUS:g} Pa, {shape}")
        zones_yaml += (f"  - {{name: {name}, stiffness: K_{name}.mtx, "
                       f"nominal_modulus: {NOMINAL_MODULUS:.17g}}}\n")
    write_channels(folder, grid)
    dofs_lines, block_lines, position_lines = [], [], []
    for cell, (i, j, k) in enumerate(cells):
        dofs = assembly.element_dofs[cell]
        kept = np.nonzero(dofs >= 0)[0]
        dofs_lines.append(f"s{zone_of[cell] + 1}," + ",".join(str(d) for d in dofs[kept]))
        block_lines.append(",".join(f"{v:.17g}" for v in stiffness[cell][np.ix_(kept, kept)].ravel()))
        position_lines.append(f"{(i + 0.5) * grid.dx:.17g},{(j + 0.5) * grid.dy:.17g},"
                              f"{(k + 0.5) * grid.dz:.17g}")
    write_text(os.path.join(folder, "element_dofs.csv"),
               "# zone, then the element's dofs (0-based); element (i, j, k) is line "
               f"(k {grid.ny} + j) {grid.nx} + i\n" + "\n".join(dofs_lines) + "\n")
    write_text(os.path.join(folder, "element_stiffness.csv"),
               f"# the element's block of K [N/m] at E = {NOMINAL_MODULUS:g} Pa, row by row\n" +
               "\n".join(block_lines) + "\n")
    write_text(os.path.join(folder, "element_positions.csv"),
               "# the element's centroid x, y, z [m]\n" + "\n".join(position_lines) + "\n")
    write_text(os.path.join(folder, "model.yaml"),
               f"# A cantilever beam {LENGTH} x {WIDTH} x {HEIGHT} m, {shape}, {grid.dofs} dofs,\n"
               "# clamped at x = 0, an oblique impact on x = L (scripts/make_beam3d_example.py)\n"
               "mass: M.mtx\n"
               f"stiffness_length: {WIDTH * HEIGHT / LENGTH:.17g}   # a* = B H / L [m]: k* = E a* "
               "is the axial stiffness\n"
               f"length: {LENGTH}\n"
               "zones:\n" + zones_yaml +
               "loads:\n  - {channel: F, vector: load_F.mtx}\n"
               "sensors_matrix:\n"
               "  - {matrix: H_displacement.mtx, channels: displacement_channels.txt}\n"
               "  - {matrix: H_strain.mtx, channels: strain_channels.txt, kind: strain}\n"
               "elements: {dofs: element_dofs.csv, stiffness: element_stiffness.csv, "
               "positions: element_positions.csv}\n")
    print(f"{folder}: {shape}, {grid.dofs} dofs")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--output", default=os.path.join(os.path.dirname(__file__), "..",
                                                         "configs", "beam3d"))
    parser.add_argument("--elements", type=int, nargs=3, default=[24, 2, 2],
                        metavar=("NX", "NY", "NZ"))
    args = parser.parse_args()
    nx, ny, nz = args.elements
    if nx % 24 or ny % 2 or nz % 2 or min(nx, ny, nz) <= 0:
        parser.error("--elements: NX must be a positive multiple of 24, NY and NZ even")
    output.set_output(quiet=True)
    write_model(args.output, Grid(nx, ny, nz))
