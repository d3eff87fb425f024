"""SfePy's displacement field on a mesh given by its nodes and cells, and its element
matrices: what scripts/make_plate_zones_example.py and scripts/make_beam3d_example.py
share. Needs SfePy (Debian's python3-sfepy)."""

import numpy as np
from sfepy.discrete import FieldVariable
from sfepy.discrete.fem import FEDomain, Field, Mesh
from sfepy.terms import Term


class VectorField:
    """A first-order vector field u and its test function v on the mesh of `coors` and
    `cells` (SfePy's cell type `desc`, e.g. "2_4" or "3_8"; one group per cell, 0 by
    default), its nodes numbered as given (checked: SfePy keeps the cells' node order)."""

    def __init__(self, name, coors, cells, desc, groups=None):
        groups = np.zeros(len(cells), np.int32) if groups is None else np.array(groups, np.int32)
        mesh = Mesh.from_data(name, coors, None, [cells], [groups], [desc])
        self.domain = FEDomain("domain", mesh)
        self.omega = self.domain.create_region("Omega", "all")
        self.field = Field.from_args("u", np.float64, "vector", self.omega, approx_order=1)
        assert np.array_equal(self.field.econn, cells), "SfePy renumbered the nodes"
        self.u = FieldVariable("u", "unknown", self.field)
        self.v = FieldVariable("v", "test", self.field, primary_var_name="u")
        self.u.set_data(np.zeros(self.u.n_dof))

    def element_matrices(self, expression, integral, region, **materials):
        """Per cell of `region`: (cell, its block), the element dofs in SfePy's field
        order (the first component of every node, then the second...)."""
        term = Term.new(expression, integral, region, v=self.v, u=self.u, **materials)
        term.setup()
        values, cells = term.evaluate(mode="weak", dw_mode="matrix", diff_var="u",
                                      ret_status=False)
        return [(int(cell), values[k, 0]) for k, cell in enumerate(cells)]
