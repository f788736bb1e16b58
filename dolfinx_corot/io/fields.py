"""Field output for ParaView: the deformed parts after every converged step (XDMF/HDF5)."""
from __future__ import annotations

import os
import re

import numpy as np

import dolfinx.fem
import dolfinx.io

from .. import _dolfinx


class FieldWriter:
    """Write the displacement (and the rotations, where the part has them) of every part of a
    scene to ``path`` (.xdmf): beams, trusses, shells, membranes and solids alike.

    Use as ``solve(scene, driver, on_step=FieldWriter(scene, "out/frame.xdmf"))``; every
    converged step is written at time = load factor, with the functions
    ``displacement`` (gdim components, P1 on the part's mesh: a quadratic solid's
    displacement is interpolated at the mesh nodes) and ``rotation`` (2D: the angle θ_z;
    3D: the rotation vector, norm ≤ π). ParaView's "Warp By Vector" shows the
    deformed shape. With ``results=True`` (the default) the element results in engineering terms
    (:meth:`dolfinx_corot.Scene.element_results`) are cell fields beside them, one per
    component, named by it: a beam's section forces N, V, M (3D: N, Vy, Vz, T, My, Mz) as the mean
    of its two ends, a shell's or membrane's resultants and face stresses, a solid's Cauchy stress,
    von Mises stress and Green–Lagrange strain at the cell's centre; cells that do not exist carry
    0. ``contacts``: contact pairs (what ``Scene.contact`` returned) whose interface pressure
    (:meth:`~dolfinx_corot.ContactPair.pressure`: nominal, both passes combined, ≥ 0 in
    compression) is written at the nodes of each side, ``contact_<pair>_slaves`` and
    ``contact_<pair>_masters`` on the part that side belongs to (0 off the interface).
    Close it (or use it in a ``with`` block) to flush the file.
    A scene whose parts live on several meshes writes one file per mesh,
    ``path`` with ``_0``, ``_1``, … before the extension.
    """

    def __init__(self, scene, path: str, model=None, results: bool = True, contacts=()):
        model = scene.model if model is None else model
        self.parts = []
        self.path = path
        if model.coupled:
            stem, ext = os.path.splitext(path)
            self.parts = [FieldWriter(scene, f"{stem}_{i}{ext}", m, results, contacts)
                          for i, m in enumerate(model.models)]
            return
        mesh = model.V.mesh
        self.model = model
        self.u = dolfinx.fem.Function(_dolfinx.function_space(mesh, "Lagrange", 1, model.gdim),
                                      name="displacement")
        self.cell_fields = {}
        if results and getattr(model, "section_components", ()):
            dg0 = _dolfinx.function_space(mesh, "DG", 0, scalar=True)
            self.cell_fields = {c: dolfinx.fem.Function(dg0, name=c) for c in model.section_components}
        # (pair, side, its surface, a scalar function on the part's nodes, its dof of each node, one at P1)
        self.pressures = []
        for pair in contacts:
            for side in ("slaves", "masters"):
                first = pair.interfaces[0]
                surface = first.slave if side == "slaves" else first.master
                if surface.part is model:
                    name = re.sub(r"\W+", "_", f"contact_{pair.name}_{side}")
                    scalar, parent = model.V.sub(0).collapse()  # parent: the V dof of each scalar dof
                    at_block = np.empty(len(parent), dtype=np.int32)
                    at_block[np.asarray(parent) // model.V.dofmap.index_map_bs] = np.arange(len(parent))
                    shown = dolfinx.fem.Function(_dolfinx.function_space(mesh, "Lagrange", 1, scalar=True), name=name)
                    self.pressures.append((pair, side, surface, dolfinx.fem.Function(scalar), at_block, shown))
        self.file = dolfinx.io.XDMFFile(mesh.comm, path, "w")
        self.file.write_mesh(mesh)

    def __call__(self, row: dict) -> None:
        if self.parts:
            for part in self.parts:
                part(row)
            return
        t = float(row["load_factor"])
        self.u.interpolate(self.model.displacement_field())
        self.file.write_function(self.u, t)
        rotation = self.model.rotation_field()
        if rotation is not None:
            self.file.write_function(rotation, t)
        if self.cell_fields:
            local = self.model.element_results(gather=False)
            for k, (name, f) in enumerate(self.cell_fields.items()):
                f.x.array[:] = 0.0
                f.x.array[f.function_space.dofmap.list.array[local.cells]] = local.values[:, :, k].mean(axis=1)
                f.x.scatter_forward()
                self.file.write_function(f, t)
        for pair, side, surface, nodal, at_block, shown in self.pressures:
            nodal.x.array[:] = 0.0
            nodal.x.array[at_block[surface.blocks]] = pair.pressure(side).pressure[surface.local]
            nodal.x.scatter_forward()
            shown.interpolate(nodal)
            self.file.write_function(shown, t)

    def close(self) -> None:
        for part in self.parts:
            part.close()
        if not self.parts:
            self.file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
