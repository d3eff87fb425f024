#!/usr/bin/env python3
"""Finds a soft zone in a steel cantilever plate with mcrewave, the plate assembled by SfePy.

What it does, in five steps:

  1. Assembles with SfePy a steel plate in plane stress, 0.4 x 0.1 m, 0.01 m thick,
     clamped on its left edge x = 0 (the clamped dofs dropped), on two meshes of
     bilinear quadrilaterals (Q4): the identification's model, 24 x 6 elements, cut into
     4 x 2 = 8 zones, and a finer truth, 48 x 12 elements. Both carry the same sensors,
     eight strain gauges (four on each long edge, one in the middle of each zone column),
     and the same load: an axial impact, a half-sine of 1000 N over 60 us, spread over
     the free edge x = 0.4 m.
  2. Makes the measurements: the truth, its zone x in [0.2, 0.3] m, y in [0, 0.05] m at
     0.7 E, is simulated by Model.response (on a time step four times finer than the
     data's), and white noise is added at SNR 20 (fixed seed).
  3. Identifies the 8 zone moduli of the model with mcrewave.identify from a config dict,
     printing its progress lines: one modulus for the whole plate first, then every zone
     at once from there.
  4. Writes into the output folder maps.png (the truth's modulus, the identified zone
     moduli, the constitutive-relation error per element at the nominal and at the
     identified moduli) and zones.csv (zone, truth, identified, relative error).
  5. Prints each zone's identified modulus against its truth, and the time taken.

Run it from the repository's root (about 15 s on one core):

    PYTHONPATH=build /usr/bin/python3 examples/plate_with_sfepy.py --output /tmp/example

Options: --output FOLDER (default: results/python_example of this checkout, which
scripts/python_example.sh regenerates), --snr (20),
--seed (1). It needs the mcrewave module (build/) and Debian's python3-sfepy,
python3-matplotlib, python3-scipy and python3-numpy. It imports the SfePy field of
scripts/sfepy_vector_field.py. Units are SI throughout: m, kg, s, N, Pa.
"""

import argparse
import csv
import math
import os
import sys
import time

import numpy as np
import scipy.sparse

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPTS = os.path.join(ROOT, "scripts")
DEFAULT_OUTPUT = os.path.join(ROOT, "results", "python_example")
sys.path.insert(0, SCRIPTS)

try:
    import matplotlib

    matplotlib.use("Agg")  # files only, no display
    import matplotlib.pyplot as plt
    from matplotlib import patheffects
    from sfepy.base.base import output as sfepy_output
    from sfepy.discrete import Integral, Material
    from sfepy.mechanics.matcoefs import stiffness_from_youngpoisson

    from sfepy_vector_field import VectorField  # scripts/: SfePy's field and element blocks
except ImportError as missing:
    sys.exit(f"plate_with_sfepy.py: {missing}: install Debian's python3-sfepy and "
             "python3-matplotlib")
try:
    import mcrewave
except ImportError:
    sys.exit("plate_with_sfepy.py: no module mcrewave: run with PYTHONPATH=build "
             "from the repository's root (the module is built with the project)")

# The plate: steel in plane stress.
LENGTH = 0.4  # [m] along x, clamped at x = 0
HEIGHT = 0.1  # [m] along y
THICKNESS = 0.01  # [m]
DENSITY = 7800.0  # [kg/m^3]
POISSON = 0.3
MODULUS = 200e9  # [Pa] the nominal Young's modulus of every zone

MODEL_MESH = (24, 6)  # elements along x and y of the identification's model
TRUTH_MESH = (48, 12)  # the truth's finer mesh (its nodes include the model's)
ZONE_GRID = (4, 2)  # zones along x and y: 8 zones of 6 x 3 model elements

# The truth: one soft region, x in [0.2, 0.3] m and y in [0, 0.05] m, at 0.7 E.
SOFT_REGION = (0.2, 0.3, 0.0, 0.05)  # [m] x_min, x_max, y_min, y_max
SOFT_FACTOR = 0.7

# The test: an axial impact on the free edge, recorded by strain gauges.
FORCE_PEAK = 1000.0  # [N]
FORCE_DURATION = 60e-6  # [s] a half-sine: its waves span several model elements
TIME_STEP = 2e-6  # [s] the data's sampling step, and the model's time step
WINDOW = 300e-6  # [s] 150 steps: about four transits of the plate's length
TRUTH_SUBSTEPS = 4  # the truth is integrated on TIME_STEP / 4
GAUGE_LENGTH = 2 * LENGTH / MODEL_MESH[0]  # [m] two model elements (33 mm)
# One gauge e_xx in the middle of each zone column, on the lower and the upper edge.
GAUGES = [(f"exx_{edge}_{column}", (column + 0.5) * LENGTH / ZONE_GRID[0], y)
          for edge, y in (("bottom", 0.0), ("top", HEIGHT)) for column in range(ZONE_GRID[0])]


class Plate:
    """The plate on an nx x ny mesh of equal rectangles, assembled by SfePy.

    Nodes row by row from the lower left, node (i, j) at (i dx, j dy). The clamped
    column i = 0 is dropped: our dofs are 2 k (u_x) and 2 k + 1 (u_y) of the k-th free
    node, nodes in the same order."""

    def __init__(self, nx, ny):
        self.nx, self.ny = nx, ny
        self.dx, self.dy = LENGTH / nx, HEIGHT / ny
        self.dofs = 2 * nx * (ny + 1)
        nodes = np.array([[i * self.dx, j * self.dy] for j in range(ny + 1) for i in range(nx + 1)])
        cells = np.array([[self.node(i, j), self.node(i + 1, j), self.node(i + 1, j + 1),
                           self.node(i, j + 1)] for j in range(ny) for i in range(nx)],
                         dtype=np.int32)
        self.centroids = nodes[cells].mean(axis=1)  # [m], element e = j nx + i
        field = VectorField("plate", nodes, cells, "2_4")
        solid = Material("solid", rho=DENSITY * THICKNESS,
                         D=THICKNESS * stiffness_from_youngpoisson(2, MODULUS, POISSON,
                                                                   plane="stress"))
        gauss = Integral("gauss", order=2)  # 2 x 2 Gauss points
        # 8 x 8 element blocks, SfePy's element dofs ordered u_x of the 4 nodes, then u_y.
        self.stiffness_blocks = np.array([block for _, block in field.element_matrices(
            "dw_lin_elastic(solid.D, v, u)", gauss, field.omega, solid=solid)])
        self.mass_blocks = np.array([block for _, block in field.element_matrices(
            "dw_dot(solid.rho, v, u)", gauss, field.omega, solid=solid)])
        # A check: the element masses add up to the plate's (each over two components).
        plate_mass = DENSITY * THICKNESS * LENGTH * HEIGHT  # [kg]
        assert abs(self.mass_blocks.sum() / 2 / plate_mass - 1) < 1e-12
        # Our dof of each element dof (-1: clamped).
        self.element_dofs = np.array([[self.dof(node % (nx + 1), node // (nx + 1), c)
                                       for c in range(2) for node in cell] for cell in cells])

    def node(self, i, j):
        return j * (self.nx + 1) + i

    def dof(self, i, j, component):
        """Our dof of node (i, j)'s u_x (component 0) or u_y (1); -1 on the clamp."""
        return -1 if i == 0 else 2 * (j * self.nx + i - 1) + component

    def dof_at(self, x, y, component):
        i, j = round(x / self.dx), round(y / self.dy)
        assert abs(i * self.dx - x) < 1e-9 and abs(j * self.dy - y) < 1e-9, (x, y)
        return self.dof(i, j, component)

    def free_block(self, element, blocks):
        """An element's dofs and block without its clamped dofs."""
        kept = self.element_dofs[element] >= 0
        return self.element_dofs[element][kept], blocks[element][np.ix_(kept, kept)]

    def assemble(self, blocks, elements):
        """The sum of the blocks of `elements` as an n x n sparse matrix."""
        rows, cols, values = [], [], []
        for element in elements:
            dofs, block = self.free_block(element, blocks)
            rows.append(np.repeat(dofs, len(dofs)))
            cols.append(np.tile(dofs, len(dofs)))
            values.append(block.ravel())
        return scipy.sparse.csr_matrix(
            (np.concatenate(values), (np.concatenate(rows), np.concatenate(cols))),
            shape=(self.dofs, self.dofs))

    def edge_load(self):
        """A unit +x resultant spread evenly over the free edge x = L (consistent forces)."""
        load = np.zeros(self.dofs)
        for j in range(self.ny):
            load[self.dof(self.nx, j, 0)] += 0.5 / self.ny
            load[self.dof(self.nx, j + 1, 0)] += 0.5 / self.ny
        return load

    def gauge_row(self, x, y):
        """The strain gauge centred at (x, y): (u_x(b) - u_x(a)) / GAUGE_LENGTH."""
        row = np.zeros(self.dofs)
        row[self.dof_at(x + GAUGE_LENGTH / 2, y, 0)] = 1.0 / GAUGE_LENGTH
        row[self.dof_at(x - GAUGE_LENGTH / 2, y, 0)] = -1.0 / GAUGE_LENGTH
        return row

    def element_map(self, values):
        """Element values as an ny x nx array for pcolormesh."""
        return np.asarray(values).reshape(self.ny, self.nx)


def zone_of(x, y):
    """The model zone (column + 4 row) of a point: zones numbered along x, row by row."""
    column = min(int(x / (LENGTH / ZONE_GRID[0])), ZONE_GRID[0] - 1)
    row = min(int(y / (HEIGHT / ZONE_GRID[1])), ZONE_GRID[1] - 1)
    return row * ZONE_GRID[0] + column


ZONE_NAMES = [f"zone_{column}_{row}" for row in range(ZONE_GRID[1])
              for column in range(ZONE_GRID[0])]


def in_soft_region(x, y):
    x_min, x_max, y_min, y_max = SOFT_REGION
    return x_min < x < x_max and y_min < y < y_max


def mcrewave_model(plate, element_zones, zone_names, name, nominal_moduli=None):
    """The plate as a mcrewave.Model: its mass, one stiffness per zone at its nominal
    modulus (MODULUS, or nominal_moduli[z] [Pa]), the load F, the gauges, and the element
    blocks that give the error map per element."""
    if nominal_moduli is None:
        nominal_moduli = [MODULUS] * len(zone_names)
    scale = np.asarray(nominal_moduli) / MODULUS  # the blocks are assembled at MODULUS
    zones = [(zone_name, scale[z] * plate.assemble(plate.stiffness_blocks,
                                                   np.flatnonzero(element_zones == z)),
              nominal_moduli[z]) for z, zone_name in enumerate(zone_names)]
    blocks = [plate.free_block(e, plate.stiffness_blocks) for e in range(len(element_zones))]
    blocks = [(dofs, scale[element_zones[e]] * block) for e, (dofs, block) in enumerate(blocks)]
    elements = {"zones": element_zones.tolist(),
                "dofs": [dofs.tolist() for dofs, _ in blocks],
                "stiffness": [block for _, block in blocks],
                "positions": plate.centroids}
    mass = plate.assemble(plate.mass_blocks, range(len(element_zones)))
    gauges = {channel: plate.gauge_row(x, y) for channel, x, y in GAUGES}
    return mcrewave.Model(mass, zones, {"F": plate.edge_load()}, gauges,
                          sensor_kinds={channel: "strain" for channel in gauges},
                          elements=elements, stiffness_length=THICKNESS, length=LENGTH,
                          name=name)


def gauge_measurements(truth, truth_moduli, snr, seed):
    """The truth's gauges under the impact, integrated on TIME_STEP / TRUTH_SUBSTEPS and
    sampled every TIME_STEP, and the impact's force, each plus white noise at `snr`
    (seeded), as mcrewave.Data."""
    samples = round(WINDOW / TIME_STEP) + 1
    fine_times = np.arange((samples - 1) * TRUTH_SUBSTEPS + 1) * (TIME_STEP / TRUTH_SUBSTEPS)
    strains = truth.response(truth_moduli, impact(fine_times)[np.newaxis, :],
                             TIME_STEP / TRUTH_SUBSTEPS)[:, ::TRUTH_SUBSTEPS]
    rng = np.random.default_rng(seed)
    strains = noisy(strains, snr, rng)
    force = noisy(impact(np.arange(samples) * TIME_STEP), snr, rng)
    channels = dict(zip(truth.sensor_channels, strains))
    channels["F"] = force
    return mcrewave.Data(channels, TIME_STEP, name=f"the truth's gauges at SNR {snr:g}")


def zone_truth_moduli(truth_plate, truth_zones, truth_moduli):
    """Each model zone's truth [Pa]: the mean of the truth's moduli over the zone (the soft
    region is one zone, so every zone is uniform in the truth)."""
    return np.array([np.mean([truth_moduli[truth_zones[e]]
                              for e, (x, y) in enumerate(truth_plate.centroids)
                              if zone_of(x, y) == z]) for z in range(len(ZONE_NAMES))])


def impact(times):
    """The impact's force history F(t) [N]: a half-sine."""
    return np.where(times <= FORCE_DURATION,
                    FORCE_PEAK * np.sin(np.pi * times / FORCE_DURATION), 0.0)


def noisy(signals, snr, rng):
    """Signals (rows of one quantity) plus white noise of std RMS(signals) / snr."""
    return signals + rng.standard_normal(signals.shape) * np.sqrt(np.mean(signals**2)) / snr


class OneLineParser(argparse.ArgumentParser):
    """Reports a bad argument on one line, with exit code 2."""

    def error(self, message):
        self.exit(2, f"{self.prog}: {message} (see --help)\n")


def positive_snr(text):
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not value > 0:  # also refuses nan
        raise argparse.ArgumentTypeError(f"expected a positive number or inf, got '{text}'")
    return value


def seed(text):
    try:
        value = int(text)
    except ValueError:
        value = -1
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a whole number >= 0, got '{text}'")
    return value


def parse_arguments():
    parser = OneLineParser(prog="plate_with_sfepy.py", description=__doc__.split("\n")[0])
    parser.add_argument("--output", default=DEFAULT_OUTPUT,
                        help="folder of maps.png and zones.csv (default: results/python_example)")
    parser.add_argument("--snr", type=positive_snr, default=20.0,
                        help="signal-to-noise ratio of the data, inf for none (default: 20)")
    parser.add_argument("--seed", type=seed, default=1, help="seed of the noise (default: 1)")
    args = parser.parse_args()
    if os.path.exists(args.output) and not os.path.isdir(args.output):
        parser.error(f"--output: '{args.output}' exists and is not a folder")
    try:
        os.makedirs(args.output, exist_ok=True)
    except OSError as error:
        parser.error(f"--output: cannot make the folder '{args.output}': {error.strerror}")
    if not os.access(args.output, os.W_OK):
        parser.error(f"--output: the folder '{args.output}' is not writable")
    return args


def main():
    args = parse_arguments()
    start = time.perf_counter()
    sfepy_output.set_output(quiet=True)

    # 1. The plates and their mcrewave models. The model's zones are the 4 x 2 grid; the
    #    truth has two zones, the sound plate and the soft region.
    model_plate, truth_plate = Plate(*MODEL_MESH), Plate(*TRUTH_MESH)
    model_zones = np.array([zone_of(x, y) for x, y in model_plate.centroids])
    truth_soft = np.array([in_soft_region(x, y) for x, y in truth_plate.centroids], dtype=int)
    model = mcrewave_model(model_plate, model_zones, ZONE_NAMES, "the 24 x 6 model")
    truth = mcrewave_model(truth_plate, truth_soft, ["sound", "soft"], "the 48 x 12 truth")
    truth_moduli = np.array([MODULUS, SOFT_FACTOR * MODULUS])  # [Pa] sound, soft
    print(f"1. assembled by SfePy: {model!r}, {truth!r} ({time.perf_counter() - start:.1f} s)")

    # 2. The measurements: the truth's gauges under the impact, on a finer time step,
    #    sampled every TIME_STEP, plus white noise on the gauges and on the force.
    data = gauge_measurements(truth, truth_moduli, args.snr, args.seed)
    print(f"2. simulated {data!r}")

    # 3. The identification. The keys are those of identify's YAML configs
    #    (identify --print-default-config); the model and the data are given in code, so
    #    the config names neither (it has no model: and no data: section).
    config = {
        "time": {"window": WINDOW, "step": TIME_STEP, "theta": 0.5},
        # The weights of the data against the constitutive gap: beta = w_e k* l*^2 for a
        # gauge (w_u k* for a displacement sensor, none here), k* = reference_modulus x
        # thickness and l* = the length (docs/matrix_models.md, section 3).
        "mcre": {"w_u": 0.01, "w_e": 0.01, "reference_modulus": MODULUS},
        # Conjugate gradients over the time steps, preconditioned on the gauges' traces.
        "inner": {"method": "streaming_conjugate_gradient", "preconditioner": "dense_traces",
                  "tolerance": 1e-8},
        # The bounds of every modulus; the first stage's scan on one thread.
        "outer": {"lower_bound": 100e9, "upper_bound": 400e9, "scan_threads": 1},
        # Every zone at once, by L-BFGS with the adjoint gradient, without a penalty.
        "zone_identification": {"optimizer": "nlopt", "algorithm": "lbfgs",
                                "regularization": "none"},
        # The moduli's standard deviation under the noise, with 2 noise draws (the least).
        "uncertainty": {"samples": 2},
    }
    print("3. identifying the 8 zone moduli:")
    identify_start = time.perf_counter()

    def progress(line):
        print(f"   [{time.perf_counter() - identify_start:5.1f} s] {line}")

    result = mcrewave.identify(config, model, data, progress=progress)
    identified = np.asarray(result.moduli)

    zone_truth = zone_truth_moduli(truth_plate, truth_soft, truth_moduli)
    relative_error = identified / zone_truth - 1.0

    # 4. The figure and the table.
    figure_path = os.path.join(args.output, "maps.png")
    table_path = os.path.join(args.output, "zones.csv")
    plot_maps(figure_path, model_plate, truth_plate, model_zones,
              truth_moduli[truth_soft], identified, result.error_maps)
    with open(table_path, "w", newline="") as table:
        writer = csv.writer(table)
        writer.writerow(["zone", "truth_Pa", "identified_Pa", "relative_error"])
        for name, true, found, error in zip(result.zone_names, zone_truth, identified,
                                            relative_error):
            writer.writerow([name, f"{true:.6g}", f"{found:.6g}", f"{error:.6f}"])
    print(f"4. wrote {figure_path} and {table_path}")

    # 5. The report.
    print(f"5. zone moduli [GPa] (E* = {result.modulus / 1e9:.2f} GPa for the whole plate "
          "first):")
    stds = [zone["std_dev"] for zone in result.summary["uncertainty"]["zones"]]
    print("   zone       truth  identified   std    error")
    for name, true, found, std, error in zip(result.zone_names, zone_truth, identified, stds,
                                             relative_error):
        print(f"   {name}  {true / 1e9:7.1f}  {found / 1e9:10.2f}  {std / 1e9:5.2f}  "
              f"{100 * error:+6.2f} %")
    weakest = result.zone_names[int(np.argmin(identified))]
    others = np.abs(np.delete(relative_error, np.argmin(zone_truth)))
    print(f"   weakest zone {weakest} (the soft one is "
          f"{ZONE_NAMES[int(np.argmin(zone_truth))]}); the others within "
          f"{100 * others.max():.2f} %")
    print(f"   identification {time.perf_counter() - identify_start:.1f} s, "
          f"{result.evaluations_count} evaluations; total {time.perf_counter() - start:.1f} s")


def plot_maps(path, model_plate, truth_plate, model_zones, truth_element_moduli,
              identified, error_maps):
    """Four maps of the plate: the truth's modulus, the identified zone moduli, and the
    error map per element at the nominal and at the identified moduli."""
    figure, axes = plt.subplots(2, 2, figsize=(13, 5.2), constrained_layout=True)
    modulus_range = {"vmin": 0.6 * MODULUS / 1e9, "vmax": 1.05 * MODULUS / 1e9,
                     "cmap": "viridis"}
    panels = [
        (axes[0, 0], truth_plate, truth_element_moduli / 1e9, modulus_range,
         "truth: Young's modulus [GPa] (48 x 12 mesh)"),
        (axes[0, 1], model_plate, identified[model_zones] / 1e9, modulus_range,
         "identified zone moduli [GPa] (24 x 6 mesh, 8 zones)"),
    ]
    for key, moduli in (("nominal_element", "the nominal 200 GPa"),
                        ("element", "the identified moduli")):
        share = np.asarray(error_maps[key])
        panels.append((axes[1, len(panels) - 2], model_plate, 100 * share / share.sum(),
                       {"cmap": "magma_r", "vmin": 0.0},
                       f"error map at {moduli} [% of e^2 per element]"))
    for axis, plate, values, style, title in panels:
        x = np.linspace(0.0, LENGTH, plate.nx + 1)
        y = np.linspace(0.0, HEIGHT, plate.ny + 1)
        mesh = axis.pcolormesh(x, y, plate.element_map(values), shading="flat", **style)
        figure.colorbar(mesh, ax=axis, shrink=0.9, pad=0.01)
        for k in range(1, ZONE_GRID[0]):
            axis.axvline(k * LENGTH / ZONE_GRID[0], color="white", lw=0.8, ls="--")
        axis.axhline(HEIGHT / 2, color="white", lw=0.8, ls="--")
        for k, (_, x_gauge, y_gauge) in enumerate(GAUGES):
            axis.plot([x_gauge - GAUGE_LENGTH / 2, x_gauge + GAUGE_LENGTH / 2], [y_gauge] * 2,
                      color="red", lw=5, solid_capstyle="butt", clip_on=False,
                      label="strain gauges" if k == 0 else None)
        axis.plot([0.0, 0.0], [0.0, HEIGHT], color="black", lw=5, clip_on=False,
                  label="clamp")
        axis.annotate("", xy=(LENGTH + 0.03, HEIGHT / 2), xytext=(LENGTH, HEIGHT / 2),
                      arrowprops={"arrowstyle": "->", "lw": 2}, annotation_clip=False)
        axis.text(LENGTH + 0.015, HEIGHT / 2 + 0.006, "F", ha="center", va="bottom")
        axis.set_aspect("equal")
        axis.set_xlim(0.0, LENGTH)
        axis.set_ylim(0.0, HEIGHT)
        axis.set_xlabel("x [m]")
        axis.set_ylabel("y [m]")
        axis.set_title(title, fontsize=10)
    for z, modulus in enumerate(identified):
        column, row = z % ZONE_GRID[0], z // ZONE_GRID[0]
        axes[0, 1].text((column + 0.5) * LENGTH / ZONE_GRID[0],
                        (row + 0.5) * HEIGHT / ZONE_GRID[1], f"{modulus / 1e9:.1f}",
                        ha="center", va="center", color="white", fontsize=10, fontweight="bold",
                        path_effects=[patheffects.withStroke(linewidth=2, foreground="black")])
    axes[0, 0].legend(loc="upper left", fontsize=8, framealpha=0.8, ncols=2)
    figure.suptitle("Cantilever plate, axial impact on x = 0.4 m: a soft zone found by "
                    "mcrewave from 8 strain gauges", fontsize=11)
    figure.savefig(path, dpi=120)
    plt.close(figure)


if __name__ == "__main__":
    try:
        main()
    except mcrewave.InputError as error:
        print(f"plate_with_sfepy.py: bad input: {error}", file=sys.stderr)
        sys.exit(2)
    except mcrewave.IdentificationError as error:
        print(f"plate_with_sfepy.py: {error}", file=sys.stderr)
        sys.exit(1)
