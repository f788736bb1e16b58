"""Pictures of a scene with PyVista, off screen: the deformed parts at several load levels over
their undeformed outline, coloured by a field.

One call draws the current state of a scene::

    dc.plot.picture(scene, "bend.png")                       # |u| on the deformed shape

and a :class:`Snapshots` recorder keeps states along a run to draw them side by side (or on
top of one another for frames)::

    shots = dc.plot.Snapshots(scene, at=(0.25, 0.5, 1.0))    # the first steps at or past these λ
    result = dc.solve(scene, driver, on_step=shots)
    shots.picture("bend_steps.png", field="rotation")

Every part kind is drawn: beams and bars as tubes of their section's radius (lines in a plane
for 2D scenes), shells and membranes as surfaces, solids by their boundary faces; cells that do
not exist in a stage are left out. Fields: ``"displacement"`` (``|u|``), ``"rotation"`` (``|θ|`` of
the nodal rotations, zero for parts without them), ``"mises"`` (the von Mises stress of solids'
cells, of shells' and membranes' larger face value, averaged at the nodes; zero for beams), or
``"contact"`` (the interface pressure of every contact pair, both passes combined, at the nodes
of either side; zero elsewhere) or ``"none"`` (one colour per part). The
undeformed shape is drawn in grey, the camera looks along z for 2D scenes and isometrically in
3D, and the colour range is shared by every state of a picture.

Section-force diagrams of frames, the way structural engineers read a lining or a beam, are
drawn by matplotlib from element results::

    fig, ax = matplotlib.pyplot.subplots()
    dc.plot.diagram(ax, scene.element_results(lining), "M")   # moments on the tension side

Capturing is collective (every rank calls it: the cells are gathered on rank 0); drawing
happens on rank 0 only. PyVista renders without a display through EGL (Debian's libegl1
and libegl-mesa0, installed by the set-up).
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field as dataclass_field
from typing import Sequence

import numpy as np
from mpi4py import MPI

__all__ = ["Snapshots", "State", "capture", "diagram", "grid_of", "picture"]

FIELDS = {"displacement": "displacement", "rotation": "rotation (rad)", "mises": "von Mises stress",
          "contact": "contact pressure", "none": None}
LINE_CELLS = ("interval",)
VTK_CELLS = {"interval": 3, "triangle": 5, "quadrilateral": 9, "tetrahedron": 10, "hexahedron": 12}


@dataclass
class State:
    """The drawing of every part of a scene at one moment (on rank 0; ``parts`` is empty on the
    others): ``label`` titles it, ``load_factor`` is where it was taken."""

    label: str
    load_factor: float | None
    parts: list = dataclass_field(default_factory=list)


def capture(scene, label: str = "", load_factor: float | None = None) -> State:
    """The current state of ``scene`` (collective)."""
    models = scene.model.models if scene.model.coupled else [scene.model]
    drawings = [m.drawing() for m in models]
    # the interface pressure of every contact pair (both passes combined) on either side's nodes
    sides = []
    for pair in getattr(scene, "pairs", []):
        for side in pair.SIDES:
            first = pair.interfaces[0]
            surface = first.slave if pair.on_slaves(side) else first.master
            sides.append((surface.part, pair.pressure(side)))  # (collective)
    for model, drawing in zip(models, drawings):
        if drawing is None or not any(part is model for part, _ in sides):
            continue
        keys = drawing["keys"]
        values = np.zeros(keys.shape)
        for part, pressure in sides:
            if part is model and len(pressure.keys):
                at = np.minimum(np.searchsorted(pressure.keys, keys), len(pressure.keys) - 1)
                hit = pressure.keys[at] == keys
                values[hit] = np.maximum(values[hit], pressure.pressure[at[hit]])
        drawing["contact"] = values
    return State(label, load_factor, [d for d in drawings if d is not None])


class Snapshots:
    """Keeps states of a scene along a run; use it as ``on_step`` of :func:`dolfinx_corot.solve`
    (a row argument) or of :func:`dolfinx_corot.staging.solve_stages` (stage, row).

    at: load factors: the first converged step at or past each (in absolute value) is kept;
    every: keep every ``every``-th step; neither: keep the last step of each stage (of a
    staged run) or of the run (call :meth:`next_run` between runs to keep each one's), captured
    at every step. :meth:`take` keeps the current state under a label.
    """

    def __init__(self, scene, at: Sequence[float] | None = None, every: int | None = None):
        self.scene = scene
        self.at = None if at is None else sorted(abs(float(a)) for a in at)
        self.every = every
        self.states: list[State] = []
        self._next = 0
        self._step = 0
        self._pending: tuple | None = None  # (stage, run) of the last state kept as "the last step"
        self._run = 0

    def __call__(self, *args) -> None:
        stage, row = (None, args[0]) if len(args) == 1 else args
        self._step += 1
        lam = float(row["load_factor"])
        name = f"{stage.name}: " if stage is not None else ""
        if self.at is None and self.every is None:  # the last step of each run or stage
            label = stage.name if stage is not None else f"λ = {lam:.3g}"
            if self.states and self._pending is not None and self._pending == (id(stage), self._run):
                self.states.pop()
            self.states.append(capture(self.scene, label, lam))
            self._pending = (id(stage), self._run)
            return
        keep = False
        if self.at is not None:
            while self._next < len(self.at) and abs(lam) >= self.at[self._next] * (1 - 1e-12):
                self._next += 1
                keep = True
        elif self.every is not None:
            keep = self._step % self.every == 0
        if keep:
            self.states.append(capture(self.scene, f"{name}λ = {lam:.3g}", lam))

    def next_run(self) -> None:
        """Start another run (without ``at`` or ``every``: its last step is kept besides the last
        run's)."""
        self._run += 1
        self._next = 0

    def take(self, label: str, load_factor: float | None = None) -> State:
        """Keep the current state under ``label`` (collective)."""
        state = capture(self.scene, label, load_factor)
        self.states.append(state)
        return state

    def picture(self, filename: str, **options) -> str | None:
        """:func:`picture` of the kept states (see there for ``options``)."""
        if not self.states:
            raise ValueError("Snapshots.picture: no state was kept (give `at` or `every`, or call take())")
        return picture(self.states, filename, **options)


def _pyvista():
    """PyVista set for off-screen rendering (EGL where there is no display)."""
    if not os.environ.get("DISPLAY"):
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import pyvista

    pyvista.OFF_SCREEN = True
    return pyvista


def grid_of(part: dict, field: str = "displacement", deformed: bool = True, scale: float = 1.0):
    """The PyVista grid of one part of a :class:`State` (its existing cells, one point per node,
    on the deformed shape unless ``deformed=False``) with the point field ``field`` (see
    :func:`picture`) as ``point_data["field"]``."""
    return _grid(_pyvista(), part, deformed, scale, field)


def _grid(pv, part: dict, deformed: bool, scale: float, field: str):
    """The PyVista dataset of one part (existing cells only) and its point field (or None)."""
    keep = np.asarray(part["exists"], dtype=bool)
    X, u = part["X"][keep], part["u"][keep]
    ncells, nv, gdim = X.shape
    # one point per node: the cells' vertices merged by their global node numbers (bodies meshed
    # apart that start in contact keep their own nodes; a node's copies on several ranks are one
    # point, though each rank computed its position with its own round-off); states without
    # the numbers: merged where both position and displacement agree
    key = np.concatenate([X, u], axis=2).reshape(-1, 2 * gdim)
    if part.get("keys") is not None:
        _, first, connectivity = np.unique(np.asarray(part["keys"])[keep].ravel(), return_index=True,
                                           return_inverse=True)
        unique = key[first]
    else:
        unique, first, connectivity = np.unique(key, axis=0, return_index=True, return_inverse=True)
    connectivity = connectivity.reshape(ncells, nv)
    points = (unique[:, :gdim] + scale * unique[:, gdim:]) if deformed else unique[:, :gdim]
    if gdim == 2:
        points = np.column_stack([points, np.zeros(len(points))])
    cells = np.column_stack([np.full(ncells, nv), connectivity]).ravel()
    grid = pv.UnstructuredGrid(cells, np.full(ncells, VTK_CELLS[part["cell"]], dtype=np.uint8), points)
    u_nodes = unique[:, gdim:]
    values = None
    if field == "displacement":
        values = np.linalg.norm(u_nodes, axis=1)
    elif field == "rotation":
        rot = part["rotation"]
        values = np.zeros(len(unique)) if rot is None else rot[keep].ravel()[first]
    elif field == "contact":
        pressure = part.get("contact")
        values = np.zeros(len(unique)) if pressure is None else np.asarray(pressure)[keep].ravel()[first]
    elif field == "mises":  # the cells' values averaged at the points they share
        mises = part.get("mises")
        values = np.zeros(len(unique))
        if mises is not None:
            count = np.bincount(connectivity.ravel(), minlength=len(unique))
            values = np.bincount(connectivity.ravel(), np.repeat(np.asarray(mises)[keep], nv),
                                 minlength=len(unique)) / np.maximum(count, 1)
    if values is not None:
        grid.point_data["field"] = values
    if part["size"] is not None:
        grid.cell_data["size"] = np.asarray(part["size"])[keep]
    return grid


def _shape(pv, grid, cell: str, gdim: int, length: float, outline: bool):
    """What is drawn of a part's grid: tubes for lines in 3D, lines in 2D, the boundary of a solid."""
    if cell in LINE_CELLS:
        lines = grid.extract_surface(algorithm=None)
        if gdim == 3 and not outline and grid.n_cells:
            size = grid.cell_data.get("size")
            radius = float(np.median(size)) if size is not None and np.any(size > 0) else 0.0
            radius = min(max(radius, 3e-3 * length), 0.02 * length)
            return lines.tube(radius=radius, n_sides=12), {}
        return lines, {"line_width": 1.5 if outline else 4.0}
    surface = grid.extract_surface(algorithm=None)
    if outline:
        return surface.extract_feature_edges(boundary_edges=True, feature_edges=cell in ("tetrahedron",
                                                                                         "hexahedron"),
                                             manifold_edges=False, non_manifold_edges=False), {"line_width": 1.0}
    return surface, {}


def picture(states, filename: str, *, field: str = "displacement", scale: float = 1.0,
            layout: str = "auto", title: str | None = None, undeformed: bool = True,
            window_size: tuple = (1400, 800), camera: str | None = None, show_edges: bool | None = None,
            columns: int = 3, clim: tuple | None = None, zoom: float = 1.0) -> str | None:
    """Draw ``states`` (a :class:`State`, a list of them, or a scene: its current state) into the
    PNG ``filename``; returns the path on rank 0, None on the others (collective when given a
    scene, which is captured first).

    field: 'displacement' (``|u|``), 'rotation' (``|θ|``), 'mises' (von Mises stress), 'contact'
    (interface pressure) or 'none'; scale: displacement magnification;
    layout: 'overlay' (every state in one view: frames), 'grid' (one view each, ``columns`` per
    row), 'auto' (overlay when every part is made of lines, else grid); undeformed: the initial
    shape in grey (a thin outline of surfaces and solids); camera: 'xy' (2D scenes' default),
    'iso' (3D default) or a PyVista camera position; show_edges: the cells' edges on surfaces
    (default: with fewer than 5000 cells); clim: the colour range (default: from 0 to the
    largest value over the states); zoom: the camera's magnification after every state has been
    fitted into the view (> 1 for shallow structures that fill a thin band). Every view of a grid
    shows the same region: the bounds of all states.
    """
    if field not in FIELDS:
        raise ValueError(f"picture: field '{field}' is not one of {list(FIELDS)}")
    if layout not in ("auto", "overlay", "grid"):
        raise ValueError(f"picture: layout '{layout}' is not one of ['auto', 'overlay', 'grid']")
    if not isinstance(states, (State, list, tuple)):
        states = capture(states, title or "")
    states = [states] if isinstance(states, State) else list(states)
    if MPI.COMM_WORLD.rank == 0 and field in ("contact", "mises") and states and \
            not any(part.get(field) is not None for state in states for part in state.parts):
        what = "contact pairs (scene.contact)" if field == "contact" else "solids, shells or membranes"
        raise ValueError(f"picture: field '{field}' draws {FIELDS[field]}, and the states hold no {what}")
    if MPI.COMM_WORLD.rank != 0:
        return None
    if not states or not states[0].parts:
        raise ValueError("picture: nothing to draw (no state, or a state without parts)")
    pv = _pyvista()
    gdim = states[0].parts[0]["gdim"]
    lines_only = all(p["cell"] in LINE_CELLS for s in states for p in s.parts)
    if layout == "auto":
        layout = "overlay" if lines_only else "grid"
    views = [states] if layout == "overlay" else [[s] for s in states]
    ncols = min(columns, len(views))
    nrows = -(-len(views) // ncols)
    # sizes and colour range over every state
    corners = np.concatenate([np.concatenate([(p["X"] + scale * p["u"]).reshape(-1, gdim), p["X"].reshape(-1, gdim)])
                              for s in states for p in s.parts if len(p["X"])])
    length = float(np.linalg.norm(corners.max(axis=0) - corners.min(axis=0))) or 1.0
    grids = [[(_grid(pv, p, True, scale, field), p) for p in s.parts] for s in states]
    if clim is None and field != "none":
        top = max((float(g.point_data["field"].max()) for gs in grids for g, _ in gs if g.n_points), default=0.0)
        clim = (0.0, top if top > 0.0 else 1.0)
    ncells = sum(len(p["X"]) for p in states[0].parts)
    edges = (ncells < 5000) if show_edges is None else show_edges
    colours = ["#4c72b0", "#dd8452", "#55a868", "#c44e52", "#8172b3", "#937860"]
    bounds = [float(v) for pair in zip(np.r_[corners.min(axis=0), [0.0] * (3 - gdim)],
                                        np.r_[corners.max(axis=0), [0.0] * (3 - gdim)]) for v in pair]
    index = {id(s): i for i, s in enumerate(states)}
    size = (max(int(window_size[0] / ncols), 200), max(int(window_size[1] / nrows), 150))
    images = []
    for view in views:  # VTK draws the shapes, one view at a time, all fitted to the same bounds
        plotter = pv.Plotter(off_screen=True, window_size=size, border=False)
        plotter.set_background("white")
        for s in view:
            for j, (grid, part) in enumerate(grids[index[id(s)]]):
                if not grid.n_cells:
                    continue
                if undeformed and (s is view[0]):
                    base = _grid(pv, part, False, scale, "none")
                    shape, style = _shape(pv, base, part["cell"], gdim, length, outline=part["cell"] not in LINE_CELLS)
                    plotter.add_mesh(shape, color="#9a9a9a", opacity=0.8, **style)
                shape, style = _shape(pv, grid, part["cell"], gdim, length, outline=False)
                kwargs = dict(style)
                if field == "none":
                    kwargs["color"] = colours[j % len(colours)]
                else:
                    kwargs.update(scalars="field", cmap="viridis", clim=clim, show_scalar_bar=False)
                if part["cell"] not in LINE_CELLS:
                    kwargs.update(show_edges=edges, edge_color="#303030", line_width=0.5 if edges else None)
                    kwargs = {k_: v for k_, v in kwargs.items() if v is not None}
                plotter.add_mesh(shape, smooth_shading=False, **kwargs)
        if gdim == 2 or camera == "xy":
            plotter.view_xy()
            plotter.enable_parallel_projection()
        elif camera in (None, "iso"):
            plotter.view_isometric()
        else:
            plotter.camera_position = camera
        plotter.reset_camera(bounds=bounds)
        if zoom != 1.0:
            plotter.camera.zoom(zoom)
        images.append(plotter.screenshot(return_img=True))
        plotter.close()
    # matplotlib lays the views out with their headings and one colour bar (VTK draws no text)
    from matplotlib import cm, colors
    from matplotlib.figure import Figure

    dpi = 100
    bar_width = 0.9 if field != "none" else 0.0
    fig = Figure(figsize=(ncols * size[0] / dpi + bar_width, nrows * size[1] / dpi + 0.6), dpi=dpi)
    grid_spec = fig.add_gridspec(nrows, ncols + (1 if bar_width else 0),
                                 width_ratios=[size[0] / dpi] * ncols + ([0.12] if bar_width else []),
                                 left=0.01, right=0.93 if bar_width else 0.99, top=0.9, bottom=0.02, wspace=0.02,
                                 hspace=0.12)
    for k, (view, image) in enumerate(zip(views, images)):
        ax = fig.add_subplot(grid_spec[k // ncols, k % ncols])
        ax.imshow(image)
        ax.set_axis_off()
        heading = view[0].label if len(view) == 1 else ", ".join(s.label for s in view if s.label)
        if heading:
            ax.set_title(heading, fontsize=11)
    heading = title or ""
    if scale != 1.0:
        heading = f"{heading} (shapes ×{scale:g})" if heading else f"shapes ×{scale:g}"
    if heading:
        fig.suptitle(heading, fontsize=13)
    if bar_width:
        axis = fig.add_subplot(grid_spec[:, ncols])
        mappable = cm.ScalarMappable(norm=colors.Normalize(*clim), cmap="viridis")
        fig.colorbar(mappable, cax=axis, label=FIELDS[field])
    folder = os.path.dirname(os.path.abspath(filename))
    os.makedirs(folder, exist_ok=True)
    fig.savefig(filename, dpi=dpi)
    return filename


# -- section-force diagrams ------------------------------------------------------------------------
def _diagram_axis(results, component: str) -> tuple[int, float]:
    """(row of ``results.axes`` along which ``component`` is drawn, sign): moments on the side of
    the fibres they put in tension (2D M > 0 and 3D Mz > 0: the −e2 fibres; My > 0: the +e3
    fibres), forces along e2 (Vz along e3) with their sign."""
    if component == "My" or component == "Vz":
        return 2, 1.0
    if component in ("M", "Mz"):
        return 1, -1.0
    return 1, 1.0


def diagram(ax, results, component: str = "M", *, scale: float | None = None, plane: Sequence[int] | None = None,
            colors: tuple[str, str] = ("tab:blue", "tab:red"), annotate: bool = True, unit: str = ""):
    """Draw the diagram of one section force of beams and bars along their current axis on the
    matplotlib axes ``ax``: each element's values at its two ends, offset normal to the element —
    moments on the side of the fibres in tension (the structural engineer's convention), normal
    and shear forces with their sign — filled in ``colors`` (positive, negative), the extreme
    value written at its place.

    results: an :class:`~dolfinx_corot.result.ElementResults` of 'section forces' (or several, drawn
    to one scale); component: one of its components (2D: N, V, M; 3D: N, Vy, Vz, T, My, Mz);
    scale: length per unit of the component (default: the largest value drawn at a tenth of the
    frame's extent); plane: the two coordinates drawn for 3D frames (default: the two of largest
    extent). Returns ``ax``."""
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Polygon

    many = list(results) if isinstance(results, (list, tuple)) else [results]
    for r in many:
        if r.kind != "section forces":
            raise ValueError(f"diagram: {r!r} holds {r.kind}; diagrams are drawn for the section forces of beams")
        if component not in r.components:
            raise ValueError(f"diagram: section forces have no component '{component}'; they have {list(r.components)}")
    points = np.concatenate([r.points.reshape(-1, r.points.shape[-1]) for r in many])
    if len(points) == 0:
        raise ValueError("diagram: no elements to draw")
    gdim = points.shape[1]
    if plane is None:
        plane = (0, 1) if gdim == 2 else tuple(sorted(np.argsort(np.ptp(points, axis=0))[-2:]))
    plane = list(plane)
    extent = float(np.ptp(points[:, plane], axis=0).max()) or 1.0
    largest = max(float(np.abs(r[component]).max(initial=0.0)) for r in many)
    if scale is None:
        scale = 0.1 * extent / largest if largest > 0 else 0.0
    row, sign = _diagram_axis(many[0], component)
    for r in many:
        x = r.points[:, :, plane]                               # (n, 2, 2)
        normal = r.axes[:, row][:, plane] if len(r) else np.zeros((0, 2))
        length = np.linalg.norm(normal, axis=1)
        normal = np.where(length[:, None] > 1e-12, normal / np.maximum(length, 1e-300)[:, None], 0.0)
        v = r[component]                                        # (n, 2)
        ax.add_collection(LineCollection(x, colors="k", linewidths=1.2, zorder=3))
        for e in range(len(r)):
            a, b = v[e]
            pieces = [(0.0, 1.0)] if a * b >= 0 else [(0.0, a / (a - b)), (a / (a - b), 1.0)]
            for t0, t1 in pieces:
                ends = [x[e, 0] + t * (x[e, 1] - x[e, 0]) for t in (t0, t1)]
                values = [a + t * (b - a) for t in (t0, t1)]
                offset = [sign * scale * val * normal[e] for val in values]
                corners = [ends[0], ends[1], ends[1] + offset[1], ends[0] + offset[0]]
                positive = (values[0] + values[1]) >= 0.0
                ax.add_patch(Polygon(corners, closed=True, facecolor=colors[0 if positive else 1], alpha=0.45,
                                     edgecolor=colors[0 if positive else 1], linewidth=0.6, zorder=2))
    if annotate and largest > 0:
        for r in many:
            v = r[component]
            if len(r) and np.abs(v).max() == largest:
                e, end = np.unravel_index(np.argmax(np.abs(v)), v.shape)
                normal = r.axes[e, row][plane]
                normal = normal / (np.linalg.norm(normal) or 1.0)
                at = r.points[e, end][plane] + sign * scale * v[e, end] * normal
                ax.annotate(f"{component} = {v[e, end]:.4g}{(' ' + unit) if unit else ''}", at, fontsize=8,
                            xytext=(4, 4), textcoords="offset points", zorder=4)
                break
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.margins(0.08)
    return ax
