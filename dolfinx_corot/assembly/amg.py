"""An AMG hierarchy kept from step to step by co-rotating its finest prolongator.

Smoothed-aggregation AMG (PETSc's GAMG) builds its prolongator P from the rigid-body modes of
the configuration it is built at: per aggregate of nodes, the translations and the infinitesimal
rotations about the aggregate, smoothed by the tangent. The large-deformation tangent at a later
configuration is nearly singular for the rigid motions of *that* configuration, and building the
hierarchy anew (aggregation, prolongator, Galerkin products with a new pattern) was a third of
the solve on the 116 k-dof block, once a step.

Seen node by node, the later configuration is the earlier one turned by the local rotation R_i of
the material around node i (the co-rotational view, as for the beams): a rigid rotation ω × (x −
c) of the new configuration is, at each node, R_i times a rigid rotation of the old one, because
x_j − x_i ≈ R_i (x⁰_j − x⁰_i) in the patch of node i. So the prolongator

    P = Q P⁰,   Q = diag(R_i) (one d × d block a node),

spans at every aggregate the rigid modes of the current configuration, with the same pattern as
P⁰ (the rows of a node share their columns) and with the same coarse coordinates of the rigid
modes (P c = Q P⁰ c): the coarser levels' prolongators still fit. So do the coarse operators:
for a tangent that is the built one turned, K = Q K⁰ Qᵀ, the Galerkin product is
Pᵀ K P = P⁰ᵀ Qᵀ Q K⁰ Qᵀ Q P⁰ = P⁰ᵀ K⁰ P⁰, the one built. The hierarchy is kept whole, only its
finest prolongator's values turned; the smoothers and CG read the current tangent (on the
116 k-dof block this made fewer CG iterations than the Galerkin products made anew on the turned
prolongator: 311 against 329). The co-rotated hierarchy is
:class:`~dolfinx_corot.assembly.petsc.LinearSolver`'s, given this module's
:class:`CorotatedProlongator`.

The rotations are those that best map each node's patch of cells from the build configuration
to the current one (least squares, as Kabsch's fit of two point sets: the polar factor of
Σ (x_j − x̄)(x⁰_j − x̄⁰)ᵀ over the patch's cells). The strain's own change is not followed;
:class:`~dolfinx_corot.assembly.system.System` builds the hierarchy anew when the CG iterations
grow (see there).
"""
from __future__ import annotations

import numpy as np
from petsc4py import PETSc

from . import petsc
from .petsc import MPIAIJArrays, SeqAIJArrays


def _compiled():
    """The compiled loops (:mod:`dolfinx_corot.assembly.cells`), or None without a compiler."""
    from . import cells

    try:
        return cells.compiled()
    except Exception:  # no compiler: numpy
        return None


def _ptr(module, kind: str, a: np.ndarray):
    return module.ffi.cast(kind + "*", a.ctypes.data)


def patch_rotations(cells: np.ndarray, before: np.ndarray, after: np.ndarray, n: int) -> np.ndarray:
    """The rotation of each of the first ``n`` nodes' patches from positions ``before`` to
    ``after`` ((nodes, d) each, every node the cells name): R_i (n, d, d), the rotation that
    minimizes Σ_c Σ_j |(x_j − x̄_c) − R (x⁰_j − x̄⁰_c)|² over the cells c around node i (x̄_c: the
    mean of cell c's nodes), the polar factor of H_i = Σ_c Σ_j (x_j − x̄_c)(x⁰_j − x̄⁰_c)ᵀ (in 3D by
    Newton's polar iteration where det H_i > 0, compiled, else from the SVD; in the plane the
    angle in closed form). A node without cells gets the identity. cells: (cells, nodes per cell) node indices."""
    cells = np.ascontiguousarray(cells, dtype=np.int32)
    before = np.ascontiguousarray(before, dtype=np.float64)
    after = np.ascontiguousarray(after, dtype=np.float64)
    d = before.shape[1]
    H = np.zeros((n, d, d))
    module = _compiled()
    if module is not None:
        module.lib.patch_moments(len(cells), cells.shape[1], _ptr(module, "int32_t", cells), d,
                                 _ptr(module, "double", before), _ptr(module, "double", after), n,
                                 _ptr(module, "double", H))
    else:
        for lo in range(0, len(cells), 8192):  # a chunk of cells at a time: small work arrays
            c = cells[lo:lo + 8192]
            a, b = before[c], after[c]
            a -= a.mean(axis=1, keepdims=True)
            b -= b.mean(axis=1, keepdims=True)
            M = np.einsum("cki,ckj->cij", b, a).reshape(len(c), d * d)
            for k in range(c.shape[1]):
                inside = c[:, k] < n
                for p in range(d * d):
                    H.reshape(n, d * d)[:, p] += np.bincount(c[inside, k], weights=M[inside, p], minlength=n)[:n]
    if d == 2:  # the turn θ that maximizes tr(RᵀH): tan θ = (H₁₀ − H₀₁) / (H₀₀ + H₁₁)
        theta = np.arctan2(H[:, 1, 0] - H[:, 0, 1], H[:, 0, 0] + H[:, 1, 1])
        c, s = np.cos(theta), np.sin(theta)
        return np.stack([np.stack([c, -s], axis=1), np.stack([s, c], axis=1)], axis=1)
    R = np.empty_like(H)
    rest = np.arange(n)
    if module is not None:  # Newton's polar iteration where det H > 0 (cells.polar3), the SVD elsewhere
        ok = np.zeros(n, dtype=np.uint8)
        module.lib.polar3(n, _ptr(module, "double", H), _ptr(module, "double", R), _ptr(module, "uint8_t", ok))
        rest = np.flatnonzero(ok == 0)
    if len(rest):
        R[rest] = _nearest_rotations(H[rest])
    return R


def _nearest_rotations(H: np.ndarray) -> np.ndarray:
    """The proper rotations R (m, 3, 3) that maximize tr(RᵀH) for each of H (m, 3, 3), from the
    SVD H = U S Vᵀ: U Vᵀ, its last axis turned where U Vᵀ reflects; the identity where H = 0."""
    U, s, Vt = np.linalg.svd(H)
    sign = np.sign(np.linalg.det(U @ Vt))
    U[:, :, -1] *= np.where(sign == 0.0, 1.0, sign)[:, None]
    R = U @ Vt
    R[s[:, 0] == 0.0] = np.eye(3)
    return R


class _RowTriples:
    """numpy's way (no compiler): the positions of a CSR block's values grouped by node, value
    m of the node's rows a = 0 … bs − 1 at ``at[a][m]`` (``node[m]``: its node)."""

    def __init__(self, indptr: np.ndarray, indices: np.ndarray, bs: int):
        nodes = (len(indptr) - 1) // bs
        length = np.diff(indptr).reshape(nodes, bs)
        if np.any(length != length[:, :1]):
            raise ValueError("the rows of a node have patterns of different lengths")
        count = length[:, 0].astype(np.int64)
        self.node = np.repeat(np.arange(nodes), count)
        offset = np.repeat(np.cumsum(count) - count, count)
        k = np.arange(int(count.sum()), dtype=np.int64) - offset
        first = indptr[:-1].reshape(nodes, bs).astype(np.int64)
        self.at = [first[self.node, a] + k for a in range(bs)]
        for a in range(1, bs):
            if np.any(indices[self.at[a]] != indices[self.at[0]]):
                raise ValueError("the rows of a node have different patterns")


class CorotatedProlongator:
    """The finest prolongator of a GAMG hierarchy just built (``pc``), its values kept, to be
    turned by nodal rotations: :meth:`rotate` sets P = diag(R_i) P⁰ in place (a compiled loop,
    or numpy without a compiler). Raises ValueError where the rows of a node do not share their
    pattern (nothing to co-rotate then)."""

    def __init__(self, pc: PETSc.PC, bs: int):
        levels = pc.getMGLevels()
        if levels < 2:
            raise ValueError("the hierarchy has one level: nothing to co-rotate")
        self.P = pc.getMGInterpolation(levels - 1)
        self.levels = levels
        self.bs = bs
        self.module = _compiled()
        self.base = []
        self.triples = []
        with self._arrays(write=False) as blocks:
            for indptr, indices, values in blocks:
                if (len(indptr) - 1) % bs:
                    raise ValueError("the prolongator's rows are not whole nodes")
                if self.module is not None:
                    m = self.module
                    if m.lib.unlike_rows((len(indptr) - 1) // bs, bs, _ptr(m, "int32_t", indptr),
                                         _ptr(m, "int32_t", indices)):
                        raise ValueError("the rows of a node have different patterns")
                else:
                    self.triples.append(_RowTriples(indptr, indices, bs))
                self.base.append(values.copy())
        # the V-cycle's restriction Pᵀ and prolongation by compiled nodal loops (PETSc's numbers,
        # each column read once a node; the prolongation's values fetched ahead): the
        # prolongation in 0.85 (116 k dofs) and 0.77 (10⁶) of PETSc's time, the restriction in
        # PETSc's time (1.6 and 33 ms a product, measured alone)
        self.transfer_products = petsc.nodal_products(self.P, bs) if self.module is not None else []

    def _arrays(self, write: bool):
        P = self.P
        if P.getType() == "seqaij":
            return _Blocks([SeqAIJArrays(P, write)])
        return _MPIBlocks(MPIAIJArrays(P, write))

    def current(self, pc: PETSc.PC) -> bool:
        """Whether ``pc``'s hierarchy is still the one this prolongator was taken from."""
        return (pc.getType() == "gamg" and pc.getMGLevels() == self.levels
                and pc.getMGInterpolation(self.levels - 1).handle == self.P.handle)

    def rotate(self, R: np.ndarray) -> None:
        """P = diag(R_i) P⁰ (R: (owned nodes, bs, bs))."""
        bs = self.bs
        R = np.ascontiguousarray(R, dtype=np.float64)
        with self._arrays(write=True) as blocks:
            for i, (indptr, _, values) in enumerate(blocks):
                base = self.base[i]
                if self.module is not None:
                    m = self.module
                    m.lib.rotate_rows((len(indptr) - 1) // bs, bs, _ptr(m, "int32_t", indptr),
                                      _ptr(m, "double", base), _ptr(m, "double", R), _ptr(m, "double", values))
                    continue
                triples = self.triples[i]
                for a in range(bs):
                    new = np.zeros(len(triples.node))
                    for b in range(bs):
                        new += R[triples.node, a, b] * base[triples.at[b]]
                    values[triples.at[a]] = new
        if self.P.getType() != "seqaij":
            self.P.assemble()  # the MPI matrix's state follows its blocks'


class _Blocks:
    def __init__(self, managers):
        self.managers = managers

    def __enter__(self):
        return [m.__enter__() for m in self.managers]

    def __exit__(self, *exc):
        for m in self.managers:
            m.__exit__(*exc)
        return False


class _MPIBlocks:
    def __init__(self, manager: MPIAIJArrays):
        self.manager = manager

    def __enter__(self):
        diagonal, off, _ = self.manager.__enter__()
        return [diagonal, off]

    def __exit__(self, *exc):
        return self.manager.__exit__(*exc)

