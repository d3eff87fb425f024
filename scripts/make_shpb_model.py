#!/usr/bin/env python3
"""Writes a split Hopkinson pressure bar as a matrix model (docs/unmeasured_loads.md section 5).

An incident bar struck at x = 0, a short specimen, a transmitted bar; linear rod elements,
consistent mass, each bar's strain gauge an observation row. The striker's force on x = 0
is a load channel nobody measured (the config declares it in mcre.unmeasured_loads, with
the interval the striker is in contact). Two ways to take the specimen:

  zone        the specimen as rod elements of its own section, density and modulus: a
              zone `specimen` beside the zone `bars` (both bars, one steel);
  force_pair  the specimen left out: the two bars are apart, and an unmeasured load
              `specimen_force` pushes them apart (-1 on the incident bar's end, +1 on the
              transmitted bar's face: the specimen's compressive force, its own law
              unknown, its mass neglected). Zone `bars` only;
  none        no specimen: the two bars joined into one (a check of the unmeasured
              striker on the same bars and gauges, docs/unmeasured_loads.md section 5).

With --poisson nu > 0 each rod carries the lateral inertia of a Rayleigh-Love rod, the
mass term rho nu^2 J int u' v' dx with J = A r^2 / 2 (a round section of radius r).

The gauge rows give the axial strain at the gauge's position x_g, interpolated linearly
between the strains of the two elements whose midpoints bracket it (second-order
accurate), so that the gauge sits where the documentation puts it whatever the mesh.

Only numpy is needed. Usage:
  /usr/bin/python3 scripts/make_shpb_model.py OUTPUT_FOLDER [--specimen zone|force_pair]
      [--incident-length 2.286] [--transmitted-length 1.8] [--bar-diameter 0.02]
      [--bar-density 7800] [--bar-modulus 210e9] [--specimen-length 0.004]
      [--specimen-diameter 0.01] [--specimen-density 1200] [--specimen-modulus 4e9]
      [--incident-gauge 1.018] [--transmitted-gauge 0.741] [--element-length 0.004]
      [--poisson 0] [--incident-channel incident_bar_strain]
      [--transmitted-channel transmitted_bar_strain]
Gauge positions are distances from the specimen's faces, as an SHPB report gives them.
"""

import argparse
import math
import os

import numpy as np


def write_text(path, text):
    with open(path + ".tmp", "w") as f:
        f.write(text)
    os.replace(path + ".tmp", path)


def write_symmetric(path, n, entries, comment):
    """entries: {(i, j): value} of a symmetric matrix (both triangles or either)."""
    lower = {}
    for (i, j), v in entries.items():
        key = (max(i, j), min(i, j))
        lower[key] = v
    items = sorted(lower.items(), key=lambda kv: (kv[0][1], kv[0][0]))
    write_text(path, "%%MatrixMarket matrix coordinate real symmetric\n% " + comment + "\n" +
               f"{n} {n} {len(items)}\n" +
               "".join(f"{i + 1} {j + 1} {v:.17g}\n" for (i, j), v in items))


def write_vector(path, values, comment):
    write_text(path, "%%MatrixMarket matrix array real general\n% " + comment + "\n" +
               f"{len(values)} 1\n" + "".join(f"{v:.17g}\n" for v in values))


def write_rows(path, rows, n, comment):
    """rows: a list of {dof: coefficient}, one per channel."""
    entries = [(r, d, v) for r, row in enumerate(rows) for d, v in sorted(row.items())]
    write_text(path, "%%MatrixMarket matrix coordinate real general\n% " + comment + "\n" +
               f"{len(rows)} {n} {len(entries)}\n" +
               "".join(f"{r + 1} {d + 1} {v:.17g}\n" for r, d, v in entries))


class Rod:
    """One rod: its first dof, node positions [m], section [m^2], density, zone, modulus."""

    def __init__(self, first_dof, start, length, elements, section, density, zone, modulus,
                 radius, poisson):
        self.first_dof = first_dof
        self.nodes = start + np.linspace(0.0, length, elements + 1)
        self.section, self.density, self.zone, self.modulus = section, density, zone, modulus
        self.radius, self.poisson = radius, poisson

    @property
    def elements(self):
        return len(self.nodes) - 1

    def dofs(self, e):
        return self.first_dof + e, self.first_dof + e + 1

    def element_length(self, e):
        return self.nodes[e + 1] - self.nodes[e]

    def stiffness(self, e):
        """E A / h [1 -1; -1 1] at the zone's nominal modulus [N/m]."""
        k = self.modulus * self.section / self.element_length(e)
        return np.array([[k, -k], [-k, k]])

    def mass(self, e):
        """rho A h / 6 [2 1; 1 2] plus the lateral inertia rho nu^2 J / h [1 -1; -1 1]."""
        h = self.element_length(e)
        m = self.density * self.section * h / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]])
        inertia = self.density * self.poisson ** 2 * self.section * self.radius ** 2 / 2.0 / h
        return m + inertia * np.array([[1.0, -1.0], [-1.0, 1.0]])

    def strain_row(self, x):
        """{dof: coefficient} of the strain at x, between the bracketing elements' strains."""
        mids = 0.5 * (self.nodes[1:] + self.nodes[:-1])
        assert mids[0] <= x <= mids[-1], f"gauge at {x} m outside the rod's element midpoints"
        k = min(int(np.searchsorted(mids, x, side="right")) - 1, self.elements - 2)
        w = (x - mids[k]) / (mids[k + 1] - mids[k])
        row = {}
        for e, weight in ((k, 1.0 - w), (k + 1, w)):
            a, b = self.dofs(e)
            h = self.element_length(e)
            row[a] = row.get(a, 0.0) - weight / h
            row[b] = row.get(b, 0.0) + weight / h
        return row


def elements_of(length, size):
    return max(2, int(math.ceil(length / size - 1e-9)))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("folder")
    p.add_argument("--specimen", choices=("zone", "force_pair", "none"), default="zone")
    p.add_argument("--incident-length", type=float, default=2.286)
    p.add_argument("--transmitted-length", type=float, default=1.8)
    p.add_argument("--bar-diameter", type=float, default=0.020)
    p.add_argument("--bar-density", type=float, default=7800.0)
    p.add_argument("--bar-modulus", type=float, default=210e9)
    p.add_argument("--specimen-length", type=float, default=0.004)
    p.add_argument("--specimen-diameter", type=float, default=0.010)
    p.add_argument("--specimen-density", type=float, default=1200.0)
    p.add_argument("--specimen-modulus", type=float, default=4e9)
    p.add_argument("--incident-gauge", type=float, default=1.018)
    p.add_argument("--transmitted-gauge", type=float, default=0.741)
    p.add_argument("--element-length", type=float, default=0.004)
    p.add_argument("--specimen-elements", type=int, default=4)
    p.add_argument("--poisson", type=float, default=0.0)
    p.add_argument("--incident-channel", default="incident_bar_strain")
    p.add_argument("--transmitted-channel", default="transmitted_bar_strain")
    a = p.parse_args()
    os.makedirs(a.folder, exist_ok=True)

    bar_radius = a.bar_diameter / 2
    bar_section = math.pi * bar_radius ** 2
    rods = []
    dof = 0
    incident = Rod(dof, 0.0, a.incident_length, elements_of(a.incident_length, a.element_length),
                   bar_section, a.bar_density, "bars", a.bar_modulus, bar_radius, a.poisson)
    rods.append(incident)
    x = a.incident_length
    if a.specimen == "zone":
        # The specimen shares the incident bar's end node and the transmitted bar's face node.
        dof = incident.first_dof + incident.elements
        specimen = Rod(dof, x, a.specimen_length, a.specimen_elements,
                       math.pi * (a.specimen_diameter / 2) ** 2, a.specimen_density, "specimen",
                       a.specimen_modulus, a.specimen_diameter / 2, a.poisson)
        rods.append(specimen)
        dof += specimen.elements
        x += a.specimen_length
    elif a.specimen == "force_pair":
        # Apart: the transmitted bar's face is a node of its own.
        dof = incident.first_dof + incident.elements + 1
        x += a.specimen_length
    else:
        # Joined: the transmitted bar starts at the incident bar's end node.
        dof = incident.first_dof + incident.elements
    transmitted = Rod(dof, x, a.transmitted_length,
                      elements_of(a.transmitted_length, a.element_length), bar_section,
                      a.bar_density, "bars", a.bar_modulus, bar_radius, a.poisson)
    rods.append(transmitted)
    n = transmitted.first_dof + transmitted.elements + 1

    mass, zones, element_lines, block_lines, position_lines = {}, {}, [], [], []
    for rod in rods:
        for e in range(rod.elements):
            i, j = rod.dofs(e)
            me, ke = rod.mass(e), rod.stiffness(e)
            zone = zones.setdefault(rod.zone, ({}, rod.modulus))[0]
            for r, dr in enumerate((i, j)):
                for c, dc in enumerate((i, j)):
                    mass[(dr, dc)] = mass.get((dr, dc), 0.0) + me[r, c]
                    zone[(dr, dc)] = zone.get((dr, dc), 0.0) + ke[r, c]
            element_lines.append(f"{rod.zone}, {i}, {j}")
            block_lines.append(", ".join(f"{v:.17g}" for v in ke.flatten()))
            position_lines.append(f"{0.5 * (rod.nodes[e] + rod.nodes[e + 1]):.17g}")

    # Checks: the mass is the rods' rho A L (the lateral inertia adds none to a rigid
    # motion), every zone's K annihilates a rigid motion of each rod.
    ones = np.ones(n)
    total = sum(v * ones[i] * ones[j] for (i, j), v in mass.items())
    expected = sum(r.density * r.section * (r.nodes[-1] - r.nodes[0]) for r in rods)
    assert abs(total - expected) <= 1e-12 * expected, (total, expected)
    for name, (entries, _) in zones.items():
        force = np.zeros(n)
        for (i, j), v in entries.items():
            force[i] += v
        assert np.abs(force).max() <= 1e-6 * max(abs(v) for v in entries.values()), name

    write_symmetric(os.path.join(a.folder, "M.mtx"), n, mass,
                    "consistent mass [kg]" + (f", Rayleigh-Love lateral inertia nu = {a.poisson}"
                                              if a.poisson > 0 else ""))
    zone_lines = []
    for name, (entries, modulus) in zones.items():
        write_symmetric(os.path.join(a.folder, f"K_{name}.mtx"), n, entries,
                        f"stiffness of zone {name} [N/m] at {modulus:.6g} Pa")
        zone_lines.append(f"  - {{name: {name}, stiffness: K_{name}.mtx, "
                          f"nominal_modulus: {modulus:.17g}}}")

    striker = np.zeros(n)
    striker[0] = 1.0
    write_vector(os.path.join(a.folder, "load_striker.mtx"), striker,
                 "the striker's force on x = 0, along +x [-]; history: channel striker [N]")
    load_lines = ["  - {channel: striker, vector: load_striker.mtx}"]
    if a.specimen == "force_pair":
        pair = np.zeros(n)
        pair[incident.first_dof + incident.elements] = -1.0
        pair[transmitted.first_dof] = 1.0
        write_vector(os.path.join(a.folder, "load_specimen_force.mtx"), pair,
                     "the specimen's compressive force on both bars' faces [-]; history: "
                     "channel specimen_force [N]")
        load_lines.append("  - {channel: specimen_force, vector: load_specimen_force.mtx}")

    gauges = [(a.incident_channel, incident, a.incident_length - a.incident_gauge),
              (a.transmitted_channel, transmitted, transmitted.nodes[0] + a.transmitted_gauge)]
    write_rows(os.path.join(a.folder, "H_strain.mtx"), [rod.strain_row(xg) for _, rod, xg in gauges],
               n, "axial strain at each gauge [-], the rows of strain_channels.txt")
    write_text(os.path.join(a.folder, "strain_channels.txt"),
               "# the rows of H_strain.mtx\n" + "".join(f"{c}\n" for c, _, _ in gauges))
    write_text(os.path.join(a.folder, "element_dofs.csv"), "\n".join(element_lines) + "\n")
    write_text(os.path.join(a.folder, "element_stiffness.csv"), "\n".join(block_lines) + "\n")
    write_text(os.path.join(a.folder, "element_positions.csv"), "\n".join(position_lines) + "\n")

    gauge_text = ", ".join(f"{c} at x = {xg:.6g} m" for c, _, xg in gauges)
    manifest = (
        f"# A split Hopkinson pressure bar (scripts/make_shpb_model.py --specimen {a.specimen}):\n"
        f"# incident bar {a.incident_length} m, "
        + (f"specimen {a.specimen_length} m (diameter {a.specimen_diameter} m), "
           if a.specimen != "none" else "no specimen, ")
        + f"transmitted bar {a.transmitted_length} m,\n"
        f"# bars of diameter {a.bar_diameter} m, elements of {a.element_length} m, {n} dofs; "
        f"gauges: {gauge_text}\n"
        "mass: M.mtx\n"
        f"stiffness_length: {bar_section / a.incident_length:.17g}   "
        "# a* = A / L_incident [m]: k* = E0 a* is the incident bar's axial stiffness\n"
        f"length: {a.incident_length:.17g}\n"
        "zones:\n" + "\n".join(zone_lines) + "\n"
        "loads:\n" + "\n".join(load_lines) + "\n"
        "sensors_matrix:\n"
        "  - {matrix: H_strain.mtx, channels: strain_channels.txt, kind: strain}\n"
        "elements: {dofs: element_dofs.csv, stiffness: element_stiffness.csv, "
        "positions: element_positions.csv}\n")
    write_text(os.path.join(a.folder, "model.yaml"), manifest)
    print(f"{a.folder}: {n} dofs, zones {', '.join(zones)}; {gauge_text}")


if __name__ == "__main__":
    main()
