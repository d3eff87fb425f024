#!/usr/bin/env python3
"""Writes the 2-D plate example of mcrewave (configs/plate/README.md) as Matrix Market files.

A cantilever plate in plane stress, clamped on its left edge x = 0, with a soft circular
inclusion, meshed with bilinear quadrilaterals (Q4, 2 x 2 Gauss points, consistent
mass), assembled here with numpy alone (no FE package needed; the element matrices are
the textbook ones, tested below against rigid-body modes and the patch test). Two
meshes of the same plate are written:

    configs/plate/coarse/  the identification's model (a few hundred dofs, committed)
    configs/plate/fine/    the truth: the mesh refined `--refine` times in each
                           direction (no inverse crime; the inclusion's outline
                           follows the finer elements)

Each folder holds M.mtx, one K_<zone>.mtx per zone at the nominal modulus, the load
vectors load_F.mtx and load_Fx.mtx (a unit transverse or axial traction resultant on
the free edge x = L; its time history is the CSV channel F), one sensor_<channel>.mtx
row per sensor, the element blocks of the error map per element (element_dofs.csv,
element_stiffness.csv, element_positions.csv), the manifests model.yaml (transverse
impact) and model_axial.yaml (axial impact) read by mcrewave (model/matrix_export.h) and
the mesh (nodes.csv, elements.csv) for drawing the error map. The clamped dofs are
eliminated.

Usage: python3 scripts/make_plate_example.py [--output configs/plate] [--nx 24 --ny 6]
       [--refine 2]
"""

import argparse
import os

import numpy as np

LENGTH = 0.4  # L [m], along x
HEIGHT = 0.1  # H [m], along y
THICKNESS = 0.01  # t [m]
DENSITY = 7800.0  # rho [kg/m^3]
POISSON = 0.3
NOMINAL_MODULUS = 200e9  # E_nominal [Pa] of every zone's K
INCLUSION_CENTRE = (0.2, 0.05)  # [m]
INCLUSION_RADIUS = 0.03  # [m]
# Sensors at points that are nodes of both meshes: (channel, kind, x, y[, x2]).
#   uy/ux: displacement of the node at (x, y);
#   exx:   strain gauge on the top edge between x and x2: (u_x(x2) - u_x(x)) / (x2 - x).
SENSORS = [
    ("uy_tip", "uy", 0.4, 0.1),
    ("uy_mid", "uy", 0.2, 0.1),
    ("ux_tip", "ux", 0.4, 0.1),
    ("exx_root", "exx", 0.05, 0.1, 0.1),
    ("exx_mid", "exx", 0.2 - 1.0 / 60.0, 0.1, 0.2 + 1.0 / 60.0),
]


def plane_stress_matrix(modulus):
    c = modulus / (1.0 - POISSON**2)
    return c * np.array([[1.0, POISSON, 0.0], [POISSON, 1.0, 0.0], [0.0, 0.0, (1.0 - POISSON) / 2]])


def q4_matrices(dx, dy, modulus):
    """Stiffness and consistent mass of a dx x dy rectangle, nodes counter-clockwise
    from the lower left, dofs (ux, uy) per node."""
    d = plane_stress_matrix(modulus)
    gauss = np.array([-1.0, 1.0]) / np.sqrt(3.0)
    xi_nodes = np.array([-1.0, 1.0, 1.0, -1.0])
    eta_nodes = np.array([-1.0, -1.0, 1.0, 1.0])
    jacobian = dx * dy / 4.0
    stiffness = np.zeros((8, 8))
    mass = np.zeros((8, 8))
    for xi in gauss:
        for eta in gauss:
            shape = 0.25 * (1 + xi * xi_nodes) * (1 + eta * eta_nodes)
            dndx = 0.25 * xi_nodes * (1 + eta * eta_nodes) * 2.0 / dx
            dndy = 0.25 * eta_nodes * (1 + xi * xi_nodes) * 2.0 / dy
            b = np.zeros((3, 8))
            b[0, 0::2] = dndx
            b[1, 1::2] = dndy
            b[2, 0::2] = dndy
            b[2, 1::2] = dndx
            stiffness += b.T @ d @ b * jacobian * THICKNESS
            n = np.zeros((2, 8))
            n[0, 0::2] = shape
            n[1, 1::2] = shape
            mass += DENSITY * THICKNESS * n.T @ n * jacobian
    return stiffness, mass


def check_element():
    """Rigid-body modes in the kernel, a uniform strain field reproduced (patch test)."""
    k, m = q4_matrices(0.02, 0.01, 1.0)
    x = np.array([0.0, 0.02, 0.02, 0.0])
    y = np.array([0.0, 0.0, 0.01, 0.01])
    rigid = [np.tile([1.0, 0.0], 4), np.tile([0.0, 1.0], 4), np.ravel(np.column_stack([-y, x]))]
    for mode in rigid:
        assert np.abs(k @ mode).max() < 1e-12 * np.abs(k).max()
    assert abs(m.sum() / 2 - DENSITY * THICKNESS * 0.02 * 0.01) < 1e-12
    assert np.allclose(k, k.T, rtol=0, atol=1e-14 * np.abs(k).max())


class Mesh:
    def __init__(self, nx, ny):
        self.nx, self.ny = nx, ny
        self.dx, self.dy = LENGTH / nx, HEIGHT / ny
        # Nodes row by row; the clamped column i = 0 is eliminated.
        self.dof = -np.ones((ny + 1, nx + 1), dtype=int)
        count = 0
        for j in range(ny + 1):
            for i in range(1, nx + 1):
                self.dof[j, i] = count
                count += 2
        self.dofs = count

    def node_at(self, x, y):
        i, j = round(x / self.dx), round(y / self.dy)
        assert abs(i * self.dx - x) < 1e-9 and abs(j * self.dy - y) < 1e-9, (x, y)
        return j, i

    def element_nodes(self, i, j):
        return [(j, i), (j, i + 1), (j + 1, i + 1), (j + 1, i)]

    def in_inclusion(self, i, j):
        cx, cy = (i + 0.5) * self.dx, (j + 0.5) * self.dy
        return (cx - INCLUSION_CENTRE[0]) ** 2 + (cy - INCLUSION_CENTRE[1]) ** 2 < INCLUSION_RADIUS**2


def assemble(mesh):
    k_element, m_element = q4_matrices(mesh.dx, mesh.dy, NOMINAL_MODULUS)
    n = mesh.dofs
    entries = {"matrix": {}, "inclusion": {}, "mass": {}}
    zones = []
    blocks = []  # per element: its kept dofs and its block of k_element on them
    for j in range(mesh.ny):
        for i in range(mesh.nx):
            zone = "inclusion" if mesh.in_inclusion(i, j) else "matrix"
            zones.append(zone)
            dofs = []
            for (nj, ni) in mesh.element_nodes(i, j):
                base = mesh.dof[nj, ni]
                dofs += [base, base + 1] if base >= 0 else [-1, -1]
            kept = [a for a in range(8) if dofs[a] >= 0]
            blocks.append(([dofs[a] for a in kept], k_element[np.ix_(kept, kept)]))
            for a in range(8):
                for b in range(8):
                    if dofs[a] < 0 or dofs[b] < 0:
                        continue
                    key = (dofs[a], dofs[b])
                    entries[zone][key] = entries[zone].get(key, 0.0) + k_element[a, b]
                    entries["mass"][key] = entries["mass"].get(key, 0.0) + m_element[a, b]
    return n, entries, zones, blocks


def write_symmetric(path, n, entries, comment):
    lower = sorted((j, i, v) for (i, j), v in entries.items() if i >= j)
    with open(path + ".tmp", "w") as f:
        f.write("%%MatrixMarket matrix coordinate real symmetric\n")
        f.write("% " + comment + "\n")
        f.write(f"{n} {n} {len(lower)}\n")
        for j, i, v in lower:
            f.write(f"{i + 1} {j + 1} {v:.17g}\n")
    os.replace(path + ".tmp", path)


def write_row(path, n, coefficients, comment):
    with open(path + ".tmp", "w") as f:
        f.write("%%MatrixMarket matrix coordinate real general\n")
        f.write("% " + comment + "\n")
        f.write(f"1 {n} {len(coefficients)}\n")
        for dof, value in sorted(coefficients.items()):
            f.write(f"1 {dof + 1} {value:.17g}\n")
    os.replace(path + ".tmp", path)


def write_vector(path, vector, comment):
    with open(path + ".tmp", "w") as f:
        f.write("%%MatrixMarket matrix array real general\n")
        f.write("% " + comment + "\n")
        f.write(f"{len(vector)} 1\n")
        for value in vector:
            f.write(f"{value:.17g}\n")
    os.replace(path + ".tmp", path)


def write_mesh(folder, refine):
    mesh = Mesh(args.nx * refine, args.ny * refine)
    os.makedirs(folder, exist_ok=True)
    n, entries, zones, blocks = assemble(mesh)
    write_symmetric(os.path.join(folder, "M.mtx"), n, entries["mass"],
                    f"consistent mass [kg], Q4 plane stress {mesh.nx} x {mesh.ny}")
    for zone in ("matrix", "inclusion"):
        write_symmetric(os.path.join(folder, f"K_{zone}.mtx"), n, entries[zone],
                        f"stiffness of zone {zone} [N/m] at E = {NOMINAL_MODULUS:g} Pa")
    # Unit transverse traction resultant (-y) on the free edge x = L, consistent nodal loads.
    load = np.zeros(n)
    for j in range(mesh.ny):
        for nj in (j, j + 1):
            load[mesh.dof[nj, mesh.nx] + 1] -= 0.5 / mesh.ny
    write_vector(os.path.join(folder, "load_F.mtx"), load,
                 "unit -y traction resultant on the edge x = L; history: channel F [N]")
    # The axial impact: a unit +x traction resultant on the same edge (model_axial.yaml).
    axial = np.zeros(n)
    for j in range(mesh.ny):
        for nj in (j, j + 1):
            axial[mesh.dof[nj, mesh.nx]] += 0.5 / mesh.ny
    write_vector(os.path.join(folder, "load_Fx.mtx"), axial,
                 "unit +x traction resultant on the edge x = L; history: channel F [N]")
    for sensor in SENSORS:
        channel, kind = sensor[0], sensor[1]
        if kind in ("ux", "uy"):
            j, i = mesh.node_at(sensor[2], sensor[3])
            row = {mesh.dof[j, i] + (1 if kind == "uy" else 0): 1.0}
        else:
            ja, ia = mesh.node_at(sensor[2], sensor[3])
            jb, ib = mesh.node_at(sensor[4], sensor[3])
            gauge = sensor[4] - sensor[2]
            row = {}
            if mesh.dof[jb, ib] >= 0:
                row[mesh.dof[jb, ib]] = 1.0 / gauge
            if mesh.dof[ja, ia] >= 0:
                row[mesh.dof[ja, ia]] = -1.0 / gauge
        write_row(os.path.join(folder, f"sensor_{channel}.mtx"), n, row,
                  f"sensor {channel} ({kind})")
    # Two manifests of the same matrices: the transverse impact (model.yaml) and the
    # axial one (model_axial.yaml), both measured as channel F.
    for manifest, vector, impact in (("model.yaml", "load_F.mtx", "transverse"),
                                     ("model_axial.yaml", "load_Fx.mtx", "axial")):
        with open(os.path.join(folder, manifest), "w") as f:
            f.write(f"# Cantilever plate {LENGTH} x {HEIGHT} x {THICKNESS} m, Q4 plane stress "
                    f"{mesh.nx} x {mesh.ny} elements, {n} dofs, {impact} impact\n")
            f.write("# (scripts/make_plate_example.py; docs/matrix_models.md)\n")
            # The scales of the MCRE weights (docs/matrix_models.md section 3): the plate's
            # thickness (in-plane stiffness ~ E t) and its length.
            f.write(f"mass: M.mtx\nstiffness_length: {THICKNESS}\nlength: {LENGTH}\nzones:\n")
            for zone in ("matrix", "inclusion"):
                f.write(f"  - {{name: {zone}, stiffness: K_{zone}.mtx, "
                        f"nominal_modulus: {NOMINAL_MODULUS:.17g}}}\n")
            f.write(f"loads:\n  - {{channel: F, vector: {vector}}}\nsensors:\n")
            for sensor in SENSORS:
                kind = ", kind: strain" if sensor[1] == "exx" else ""
                f.write(f"  - {{channel: {sensor[0]}, row: sensor_{sensor[0]}.mtx{kind}}}\n")
            f.write("elements: {dofs: element_dofs.csv, stiffness: element_stiffness.csv, "
                    "positions: element_positions.csv}\n")
    # The element blocks of the error map per element (docs/matrix_models.md section 4):
    # each element's zone and kept dofs (the clamped ones eliminated), its block of
    # K_<zone> at the nominal modulus, and its centroid.
    with open(os.path.join(folder, "element_dofs.csv"), "w") as f:
        f.write("# zone, then the element's dofs (0-based), elements as in elements.csv\n")
        for zone, (dofs, _) in zip(zones, blocks):
            f.write(f"{zone},{','.join(map(str, dofs))}\n")
    with open(os.path.join(folder, "element_stiffness.csv"), "w") as f:
        f.write(f"# the element's block of K [N/m] at E = {NOMINAL_MODULUS:g} Pa, row by row\n")
        for _, block in blocks:
            f.write(",".join(f"{value:.17g}" for value in block.ravel()) + "\n")
    with open(os.path.join(folder, "element_positions.csv"), "w") as f:
        f.write("# the element's centroid x, y [m]\n")
        for j in range(mesh.ny):
            for i in range(mesh.nx):
                f.write(f"{(i + 0.5) * mesh.dx:.17g},{(j + 0.5) * mesh.dy:.17g}\n")
    with open(os.path.join(folder, "nodes.csv"), "w") as f:
        f.write("node,x,y,dof_x,dof_y\n")
        for j in range(mesh.ny + 1):
            for i in range(mesh.nx + 1):
                d = mesh.dof[j, i]
                f.write(f"{j * (mesh.nx + 1) + i},{i * mesh.dx:.17g},{j * mesh.dy:.17g},"
                        f"{d if d >= 0 else -1},{d + 1 if d >= 0 else -1}\n")
    with open(os.path.join(folder, "elements.csv"), "w") as f:
        f.write("element,n0,n1,n2,n3,zone\n")
        for j in range(mesh.ny):
            for i in range(mesh.nx):
                nodes = [nj * (mesh.nx + 1) + ni for (nj, ni) in mesh.element_nodes(i, j)]
                f.write(f"{j * mesh.nx + i},{','.join(map(str, nodes))},"
                        f"{zones[j * mesh.nx + i]}\n")
    inclusion = zones.count("inclusion")
    print(f"{folder}: {mesh.nx} x {mesh.ny} elements ({inclusion} in the inclusion), {n} dofs, "
          f"{len(entries['mass'])} mass entries")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--output", default=os.path.join(os.path.dirname(__file__), "..",
                                                         "configs", "plate"))
    parser.add_argument("--nx", type=int, default=24)
    parser.add_argument("--ny", type=int, default=6)
    parser.add_argument("--refine", type=int, default=2)
    args = parser.parse_args()
    check_element()
    write_mesh(os.path.join(args.output, "coarse"), 1)
    write_mesh(os.path.join(args.output, "fine"), args.refine)
