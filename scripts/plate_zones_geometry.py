"""The geometry of the many-zone plate example (configs/plate_zones/README.md): its
dimensions, meshes, truths and point sensors, shared by scripts/make_plate_zones_example.py
(which assembles it with SfePy) and scripts/plate_zones_study.py (which compares the
identified zones with the truths). Plain Python: no package needed."""

LENGTH = 0.4  # L [m], along x
HEIGHT = 0.1  # H [m], along y
THICKNESS = 0.01  # t [m]
DENSITY = 7800.0  # rho [kg/m^3]
POISSON = 0.3
NOMINAL_MODULUS = 200e9  # [Pa]
MODEL_ELEMENTS = (48, 12)
REFINE = 2


def circle(cx, cy, radius):
    return lambda x, y: (x - cx) ** 2 + (y - cy) ** 2 < radius**2


def box(x0, x1, y0, y1):
    return lambda x, y: x0 < x < x1 and y0 < y < y1


# Each truth: its zones other than the matrix, (name, modulus / E, shape).
TRUTHS = {
    "soft_inclusion": [("inclusion", 0.7, circle(0.26, 0.055, 0.022))],
    "two_inclusions": [("soft", 0.7, circle(0.12, 0.04, 0.02)),
                       ("stiff", 1.3, circle(0.29, 0.065, 0.018))],
    "soft_band": [("band", 0.5, box(0.2125, 0.2125 + 1.0 / 120.0, 0.0, 0.0625))],
}

# Point sensors at nodes of both meshes: (channel, kind, x, y[, x2]); ux / uy a node's
# displacement, exx a gauge on an edge between x and x2: (u_x(x2) - u_x(x)) / (x2 - x).
GAUGE = 1.0 / 60.0
POINT_SENSORS = [
    ("uy_tip", "uy", 0.4, 0.1),
    ("ux_tip", "ux", 0.4, 0.1),
    ("ux_tip_bottom", "ux", 0.4, 0.0),
    ("uy_mid_top", "uy", 0.2, 0.1),
    ("uy_mid_bottom", "uy", 0.2, 0.0),
    ("exx_top_1", "exx", 0.1 - GAUGE / 2, 0.1, 0.1 + GAUGE / 2),
    ("exx_top_2", "exx", 0.2 - GAUGE / 2, 0.1, 0.2 + GAUGE / 2),
    ("exx_top_3", "exx", 0.3 - GAUGE / 2, 0.1, 0.3 + GAUGE / 2),
    ("exx_bottom_1", "exx", 0.1 - GAUGE / 2, 0.0, 0.1 + GAUGE / 2),
    ("exx_bottom_3", "exx", 0.3 - GAUGE / 2, 0.0, 0.3 + GAUGE / 2),
]


class Grid:
    """An nx x ny mesh of equal rectangles, nodes row by row (node j (nx + 1) + i at
    (i dx, j dy)); the clamped column i = 0 eliminated, dofs 2 k, 2 k + 1 (ux, uy) of the
    k-th free node in that order."""

    def __init__(self, nx, ny):
        self.nx, self.ny = nx, ny
        self.dx, self.dy = LENGTH / nx, HEIGHT / ny
        self.dofs = 2 * (ny + 1) * nx

    def node(self, i, j):
        return j * (self.nx + 1) + i

    def node_at(self, x, y):
        i, j = round(x / self.dx), round(y / self.dy)
        assert abs(i * self.dx - x) < 1e-9 and abs(j * self.dy - y) < 1e-9, (x, y)
        return i, j

    def dof(self, i, j, component):
        """Our dof of node (i, j)'s component (0: x, 1: y); -1 on the clamped edge."""
        return -1 if i == 0 else 2 * (j * self.nx + i - 1) + component

    def centroid(self, cell):
        i, j = cell % self.nx, cell // self.nx
        return (i + 0.5) * self.dx, (j + 0.5) * self.dy
