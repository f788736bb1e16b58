"""FieldWriter on every part kind: the XDMF file read back with meshio holds the computed values."""
import re

import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot import rotations
from dolfinx_corot.io.gmsh_models import polyline
from dolfinx_corot.io.mesh import box, from_arrays, rectangles

comm = MPI.COMM_WORLD
meshio = pytest.importorskip("meshio")


def _beam2d():
    tm = polyline([[0.0, 0.0], [1.0, 0.0]], 6, line_name="beam")
    sc = dc.Scene()
    b = sc.add_beam(tm, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1e3))
    sc.fix(b, "base")
    sc.load(b, "tip", moment=0.005)
    return sc


def _beam3d():
    tm = polyline([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], 6, line_name="beam", gdim=3)
    sc = dc.Scene()
    b = sc.add_beam(tm, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1e3), orientation=(0, 1, 0))
    sc.fix(b, "base")
    sc.load(b, "tip", force=(0.0, 0.002, 0.001), moment=(0.002, 0.0, 0.001))
    return sc


def _plate(quads):
    n = 4
    x, y = np.meshgrid(np.linspace(0, 1, n + 1), np.linspace(0, 1, n + 1))
    pts = np.column_stack([x.ravel(), y.ravel(), 0.0 * x.ravel()])
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    q = np.column_stack([idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(), idx[1:, :-1].ravel()])
    cells = q if quads else np.vstack([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    left = np.flatnonzero(np.isclose(pts[:, 0], 0.0))
    right = np.flatnonzero(np.isclose(pts[:, 0], 1.0))
    tm = from_arrays(pts, cells, "plate", point_groups={"left": left, "right": right, "all": np.arange(len(pts))}, comm=comm)
    sc = dc.Scene()
    if quads:
        p = sc.add_membrane(tm, "plate", thickness=0.01, material=dc.Elastic(1e3, 0.3))
        sc.fix(p, "left")
        sc.fix(p, "all", dofs=("uz",))  # a flat membrane has no stiffness out of its plane
        sc.load(p, "right", force=(0.1, 0.02, 0.0))
    else:
        p = sc.add_shell(tm, "plate", thickness=0.05, material=dc.Elastic(1e3, 0.3))
        sc.fix(p, "left")
        sc.load(p, "right", force=(0.0, 0.0, 0.01))
    return sc


def _solid2d():
    tm = rectangles({"block": (0.0, 0.0, 2.0, 1.0, 4, 2)}, {"bottom": [("block", "bottom")]}, comm=comm)
    sc = dc.Scene()
    b = sc.add_solid(tm, material=dc.SaintVenantKirchhoff(10.0, 0.3), degree=1)
    sc.fix(b, "bottom")
    sc.gravity(b, (0.3, -1.0), 1.0)
    return sc


def _solid3d_quadratic():
    tm = box((2.0, 1.0, 1.0), (2, 1, 1), comm=comm)
    sc = dc.Scene()
    b = sc.add_solid(tm, material=dc.NeoHookean(10.0, 0.3), degree=2)
    sc.fix(b, "x0")
    sc.gravity(b, (0.0, 0.0, -1.0), 1.0)
    return sc


SCENES = {"beam 2D": _beam2d, "beam 3D": _beam3d, "shell": lambda: _plate(False),
          "quad membrane": lambda: _plate(True), "solid 2D": _solid2d, "solid 3D P2": _solid3d_quadratic}


def _read_xdmf(path):
    """(time, points, point data) of the last step of an XDMF time series written by DOLFINx (one
    temporal collection per function), read from the XML and the HDF5 file; meshio reads the same
    points where it knows the topology (not PolyLine: meshes of lines)."""
    import os
    import xml.etree.ElementTree as ET

    import h5py

    def dataset(item):
        file, name = item.text.strip().split(":")
        with h5py.File(os.path.join(os.path.dirname(path), file), "r") as h5:
            return h5[name][...]

    root = ET.parse(path).getroot()
    points = dataset(root.find(".//Geometry/DataItem"))
    data, times = {}, {}
    for grid in root.iter("Grid"):
        time, attribute = grid.find("Time"), grid.find("Attribute")
        if time is not None and attribute is not None:
            name, t = attribute.get("Name"), float(time.get("Value"))
            if t >= times.get(name, -np.inf):
                times[name], data[name] = t, dataset(attribute.find("DataItem"))
    assert len(set(times.values())) == 1, times
    if root.find(".//Topology").get("TopologyType") != "PolyLine":
        mesh_points, _ = meshio.xdmf.TimeSeriesReader(path).read_points_cells()
        np.testing.assert_array_equal(mesh_points, points)
    return max(times.values()), points, data


def _check_file(path, model):
    """The last step of the file holds the part's displacement (and rotation) at its nodes, and its
    element results as cell fields (each cell's mean over its points; compared as sorted sets of
    values, the file's cell order being the ranks' local orders)."""
    X, state = model.nodes()   # every rank: all nodes (of V) with their state
    results = model.element_results()
    if comm.rank != 0:
        return
    t, points, point_data = _read_xdmf(path)
    assert t == pytest.approx(1.0)
    g = model.gdim
    # match the file's points with the part's nodes by position
    d = np.linalg.norm(points[:, None, :g] - X[None, :, :g], axis=2)
    node = d.argmin(axis=1)
    assert np.all(d[np.arange(len(points)), node] < 1e-12)
    u = point_data["displacement"][:, :g]
    np.testing.assert_allclose(u, state[node, :g], atol=1e-12 * max(1.0, np.abs(state[:, :g]).max()))
    assert np.abs(u).max() > 1e-4  # something moved
    nr = model.ndof - model.translations
    if nr == 1:
        np.testing.assert_allclose(point_data["rotation"].ravel(), state[node, 2], atol=1e-12)
    elif nr == 3:
        expect = np.array([rotations.rotvec_from_quat(q.copy()) for q in state[node, 3:7]])
        np.testing.assert_allclose(point_data["rotation"], expect, atol=1e-12)
        assert np.abs(expect).max() > 1e-4 or not model.bending_blocks().any()  # membranes: fixed
    else:
        assert "rotation" not in point_data
    for k, name in enumerate(results.components):
        np.testing.assert_allclose(np.sort(point_data[name].ravel()), np.sort(results.values[:, :, k].mean(axis=1)),
                                   rtol=1e-12, atol=1e-12 * np.abs(results.values).max(), err_msg=name)
    assert np.abs(results.values).max() > 0.0


@pytest.mark.parametrize("kind", sorted(SCENES))
def test_field_writer_writes_every_part_kind(kind, tmp_path):
    sc = SCENES[kind]()
    path = comm.bcast(str(tmp_path / "fields.xdmf") if comm.rank == 0 else None, root=0)
    with dc.io.FieldWriter(sc, path) as writer:
        dc.solve(sc, dc.LoadControl(steps=2), on_step=writer)
    _check_file(path, sc.model)


def test_field_writer_writes_one_file_per_mesh_of_a_coupled_scene(tmp_path):
    sc = _solid2d()
    tm = polyline([[0.0, 1.5], [2.0, 1.5]], 4, line_name="beam")
    b = sc.add_beam(tm, "beam", section=dc.Rectangle(0.1, 0.1), material=dc.Elastic(1e3))
    sc.fix(b, "base")
    sc.load(b, "tip", force=(0.0, -0.01))
    path = comm.bcast(str(tmp_path / "scene.xdmf") if comm.rank == 0 else None, root=0)
    with dc.io.FieldWriter(sc, path) as writer:
        dc.solve(sc, dc.LoadControl(steps=1), on_step=writer)
    for i, model in enumerate(sc.model.models):
        _check_file(path.replace(".xdmf", f"_{i}.xdmf"), model)


def test_field_writer_writes_the_interface_pressure_at_the_nodes_of_each_side(tmp_path):
    """Two blocks pressed together by a uniform stress P (the two-pass patch test of
    test_contact_pressure.py): the contact pressure written at the nodes of both interface sides is P
    (to the Newton tolerance), 0 at every other node."""
    from test_contact_pressure import EXACT, P, _blocks

    sc, b = _blocks(3, 4)
    pair = sc.contact(slaves=(b, "upper_bottom"), masters=(b, "lower_top"), law=EXACT, symmetric=True, smooth=False)
    path = comm.bcast(str(tmp_path / "contact.xdmf") if comm.rank == 0 else None, root=0)
    with dc.io.FieldWriter(sc, path, contacts=[pair]) as writer:
        dc.solve(sc, dc.LoadControl(steps=1), on_step=writer)
    X, _ = b.model.nodes()
    if comm.rank != 0:
        return
    _, points, data = _read_xdmf(path)
    on = np.isclose(points[:, 1], 1.0)  # the upper block's 5 nodes there and the lower one's 4
    assert on.sum() == 9
    for side, nodes in (("slaves", 5), ("masters", 4)):
        p = data[re.sub(r"\W+", "_", f"contact_{pair.name}_{side}")].ravel()
        assert np.sum(np.abs(p[on] / P - 1.0) < 1e-7) == nodes  # the side's nodes: P; the other's: 0
        assert np.sum(np.abs(p[on]) < 1e-12 * P) == 9 - nodes and np.all(np.abs(p[~on]) < 1e-12 * P)
