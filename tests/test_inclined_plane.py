"""The inclined plane (issue 16): an elastic block resting under its own weight on a table that
tilts, in 2D and 3D. The table's tilt θ is the angle of the gravity to the table's normal: the
weight W along the normal is applied in the first step, then the component W tan θ along the
table grows with the load factor (a rigid rotation of the whole problem; in 3D obliquely to the
meshes, along (2, 1)). Reference: Coulomb's law, μ = 0.3. The block stays while tan θ < μ — it
deforms as the block with its bottom held (the elastic solution, a converged run of the same
mesh) and the contact alone carries the weight — and slides once tan θ > μ: no static
equilibrium is left; the stabilisation springs of the block (``Scene.stabilise``, released after
each solve while the block is held) then carry the part of the weight the interface cannot,
(tan θ − μ) W, and the block creeps on them far beyond the elastic displacement."""
import numpy as np
import pytest
from mpi4py import MPI

import dolfinx_corot as dc
from dolfinx_corot.io.mesh import rectangles

comm = MPI.COMM_WORLD
E, NU, MU, W, STEPS = 1.0, 0.3, 0.3, 1e-3, 20
TAN_MAX = 0.301  # tan θ at the last step; at the one before: 0.285
ALONG = np.array([2.0, 1.0]) / np.sqrt(5.0)  # the downhill direction of the 3D table


def _tilted(dim: int, held: bool):
    """A block (2D: 1 × 1, 4 × 4 quadrilaterals; 3D: 1 × 1 × 0.5 of tetrahedra, spacing 0.25) of
    unit density on a base 10⁴ times stiffer, fixed at its bottom; the block's own weight as
    above; ``held``: the block's bottom fixed instead of contact."""
    if dim == 2:
        tm = rectangles({"base_block": (0.0, 0.0, 4.0, 1.0, 24, 2), "slider": (0.5, 1.0, 1.0, 1.0, 4, 4)},
                        {"base": [("base_block", "bottom")], "base_top": [("base_block", "top")],
                         "slider_bottom": [("slider", "bottom")], "top": [("slider", "top")]}, comm=comm)
        sc = dc.Scene()
        down, downhill = (0.0, -W), (W * TAN_MAX, 0.0)
    else:
        from test_contact3d import _slider_3d
        tm = _slider_3d(False)
        sc = dc.Scene(large_rotations=True, linear_solver="direct")
        down, downhill = (0.0, 0.0, -W), (*(W * TAN_MAX * ALONG), 0.0)
    block = sc.add_solid(tm, "slider", material=dc.SaintVenantKirchhoff(E, NU), degree=1)
    base = sc.add_solid(tm, "base_block", material=dc.SaintVenantKirchhoff(1e4 * E, NU), degree=1)
    sc.fix(base, "base")
    sc.gravity(block, down, density=1.0, amplitude=dc.Amplitude(((0.0, 0.0), (1 / STEPS, 1.0), (1.0, 1.0))))
    sc.gravity(block, downhill, density=1.0, amplitude=dc.Amplitude(((0.0, 0.0), (1 / STEPS, 0.0), (1.0, 1.0))))
    if held:
        sc.fix(block, "slider_bottom")
    else:
        sc.contact((block, "slider_bottom"), (base, "base_top"), law=dc.AugmentedLagrangian(gap_tolerance=1e-8),
                   friction=dc.Coulomb(mu=MU))
        sc.stabilise(block)
    sc.monitor_reaction("table", base, "base")
    sc.monitor("top", block, "top", reduce="mean")
    return sc


@pytest.mark.parametrize("dim", [2, 3])
def test_a_block_stays_on_a_tilting_table_until_tan_theta_is_mu_then_slides(dim):
    """While tan θ < μ (19 steps, up to 0.285): the table's reaction is the block's weight, tangential
    over normal = tan θ to 1e-6 (the stabilisation springs carry nothing: below 1e-8 of the load),
    and the block's downhill displacement (mean over its top) is bounded by the held block's: at
    most 1.5 times it (measured: 1.026 rising to 1.038 in 2D, the tangential penalty's compliance
    then partial slip at the block's edges; 1.07 to 1.27 in 3D, where the held block's bottom
    also resists the Poisson expansion). At tan θ = 0.301 > μ the block slides: the interface
    carries μ W to 1e-6 (the table's reaction, along the downhill direction to 1e-6), the
    springs the rest, and the block has moved more than 50 times the held block's displacement
    (measured 68 and 223 times). No cut."""
    scene = _tilted(dim, held=False)
    h = dc.solve(scene, dc.LoadControl(steps=STEPS)).history
    held = dc.solve(_tilted(dim, held=True), dc.LoadControl(steps=STEPS)).history
    axes = "xyz"[:dim]
    force = np.column_stack([h.column(f"table_F{a}") for a in axes])
    u = np.column_stack([h.column(f"top_u{a}_mean") for a in axes])[:, :-1]
    u_held = np.column_stack([held.column(f"top_u{a}_mean") for a in axes])[:, :-1]
    downhill = np.array([1.0]) if dim == 2 else ALONG
    tan = TAN_MAX * np.clip(h.column("load_factor") - 1 / STEPS, 0.0, None) / (1 - 1 / STEPS)
    assert h.column("cuts").sum() == 0 and len(tan) == STEPS
    ratio = -force[:, :-1] @ downhill / force[:, -1]  # the table pushes the block uphill
    stays = tan < MU
    assert stays[:-1].all() and not stays[-1]
    assert np.abs(ratio[stays] - tan[stays]).max() < 1e-6 * MU
    assert h.column("stab_force")[stays].max() < 1e-8
    along, along_held = u @ downhill, u_held @ downhill
    assert np.all(along[1:-1] <= 1.5 * along_held[1:-1]), along[1:-1] / along_held[1:-1]
    # beyond the angle of friction
    assert ratio[-1] == pytest.approx(MU, rel=1e-6)
    assert np.linalg.norm(force[-1, :-1] + ratio[-1] * force[-1, -1] * downhill) < 1e-6 * MU * abs(force[-1, -1])
    assert h.column("stab_force")[-1] > 1e-5
    assert along[-1] > 50.0 * along_held[-1]
    # the slaves' friction (Interface.friction_traction): all slip, each at |t| = μ p, their
    # tractions sum to the interface's force, μ N downhill (the force on the block is −t)
    itf = scene.interfaces[0]
    _, p = itf.pressure()
    _, t, slipping = itf.friction_traction()
    on = p > 0.0
    assert on.sum() >= 5 and slipping[on].all() and not slipping[~on].any()
    size = np.abs(t) if dim == 2 else np.linalg.norm(t, axis=1)
    assert np.allclose(size[on], MU * p[on], rtol=1e-9, atol=0.0)
    t_along = t if dim == 2 else t[:, :2] @ ALONG  # (in 2D along the base's numbering, here −x)
    assert abs(np.sum(itf.area * t_along)) == pytest.approx(MU * abs(force[-1, -1]), rel=1e-6)
