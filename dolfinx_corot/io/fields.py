"""Field output for ParaView: the deformed structure after every converged step (XDMF/HDF5)."""
from __future__ import annotations

import os

import numpy as np

import dolfinx.fem
import dolfinx.io

from .. import rotations


class FieldWriter:
    """Write displacement and rotation of a scene's structural model to ``path`` (.xdmf).

    Use as ``solve(scene, driver, on_step=FieldWriter(scene, "out/frame.xdmf"))``; every
    converged step is written at time = load factor, with the functions
    ``displacement`` (gdim components) and ``rotation`` (2D: the angle θ_z; 3D: the
    rotation vector, norm ≤ π). ParaView's "Warp By Vector" shows the deformed
    shape. Close it (or use it in a ``with`` block) to flush the file.
    A scene whose parts live on several meshes writes one file per mesh,
    ``path`` with ``_0``, ``_1``, … before the extension.
    """

    def __init__(self, scene, path: str, model=None):
        model = scene.model if model is None else model
        self.parts = []
        if hasattr(model, "models"):
            stem, ext = os.path.splitext(path)
            self.parts = [FieldWriter(scene, f"{stem}_{i}{ext}", m) for i, m in enumerate(model.models)]
            return
        mesh = model.V.mesh
        self.model = model
        g = model.gdim
        self.u = dolfinx.fem.Function(dolfinx.fem.VectorFunctionSpace(mesh, ("Lagrange", 1), dim=g),
                                      name="displacement")
        nr = 1 if g == 2 else 3
        space = dolfinx.fem.FunctionSpace(mesh, ("Lagrange", 1)) if nr == 1 else \
            dolfinx.fem.VectorFunctionSpace(mesh, ("Lagrange", 1), dim=3)
        self.r = dolfinx.fem.Function(space, name="rotation")
        self.file = dolfinx.io.XDMFFile(mesh.comm, path, "w")
        self.file.write_mesh(mesh)

    def __call__(self, row: dict) -> None:
        if self.parts:
            for part in self.parts:
                part(row)
            return
        st = self.model.state.x.array.reshape(-1, self.model.state_size)
        g = self.model.gdim
        self.u.x.array.reshape(-1, g)[:] = st[:, :g]
        if g == 2:
            self.r.x.array[:] = st[:, 2]
        else:
            self.r.x.array.reshape(-1, 3)[:] = np.array([rotations.rotvec_from_quat(q.copy()) for q in st[:, 3:7]])
        t = float(row["load_factor"])
        self.file.write_function(self.u, t)
        self.file.write_function(self.r, t)

    def close(self) -> None:
        for part in self.parts:
            part.close()
        if not self.parts:
            self.file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
