r"""Contact search in 3D: broad phase of slave points against the boxes of master faces.

Pure numpy + numba. The master surface is a set of faces (triangles or quadrilaterals, or a
face with a thickness: a shell or a beam's offset surface) given by their axis-aligned bounding
boxes ``lo[j]``, ``hi[j]`` (current configuration, inflated by the caller's margin and any
offset); the slaves are points. The broad phase returns every pair (slave, face) whose slave lies
in the face's closed box — the narrow phase (closest point on the face, :mod:`.kernels3d`) is
done on these candidates only.

It is the bucket search of :mod:`.search` in three dimensions (Benson & Hallquist 1990; Munjiza &
Andrews 1998, NBS): the slaves are binned into the one cell of a uniform grid that contains them
and sorted by cell key ``(ix · ny + iy) · nz + iz`` (radix sort, O(ns)); every face visits the
(ix, iy) columns its box overlaps and reads, in each, the slaves of its z range by two binary
searches. With the cell size the mean box size, a face visits a few columns, so the work is
O(ns + nm log ns + slaves tested), memory O(ns + nm + pairs), and no dense grid exists (a large
extent or very different face sizes cost nothing but the columns a box spans). The pairs come
out sorted by slave, then face.

References: P. Wriggers, *Computational Contact Mechanics*, 2nd ed., Springer 2006, §9.2
(global and local search); V. A. Yastrebov, *Numerical Methods in Contact Mechanics*, ISTE/Wiley
2013, ch. 4 (contact detection).
"""
from __future__ import annotations

import math

import numba
import numpy as np

from .search import _column_range, _column_table, _pairs_by_slave, _reserve, _sort_keys

__all__ = ["broad_phase_boxes", "face_boxes"]

_MAX_CELLS_PER_AXIS = float(2**20)  # keeps cell keys (ix ny + iy) nz + iz below 2**60


@numba.njit(cache=True)
def _broad_phase_kernel(slaves, lo, hi):
    ns = slaves.shape[0]
    nm = lo.shape[0]
    if ns == 0 or nm == 0:
        return np.empty((0, 2), dtype=np.int64)
    size = 0.0
    for j in range(nm):
        size += max(hi[j, 0] - lo[j, 0], max(hi[j, 1] - lo[j, 1], hi[j, 2] - lo[j, 2]))
    h = size / nm
    smin = np.empty(3)
    smax = np.empty(3)
    for k in range(3):
        smin[k] = slaves[0, k]
        smax[k] = slaves[0, k]
    for i in range(1, ns):
        for k in range(3):
            smin[k] = min(smin[k], slaves[i, k])
            smax[k] = max(smax[k], slaves[i, k])
    ext = max(smax[0] - smin[0], max(smax[1] - smin[1], smax[2] - smin[2]))
    if not h > 0.0:  # point boxes only
        h = ext / ns if ext > 0.0 else 1.0
    if ext / h > _MAX_CELLS_PER_AXIS:
        h = ext / _MAX_CELLS_PER_AXIS
    nx = math.floor((smax[0] - smin[0]) / h) + 1
    ny = math.floor((smax[1] - smin[1]) / h) + 1
    nz = math.floor((smax[2] - smin[2]) / h) + 1
    keys = np.empty(ns, dtype=np.int64)
    for i in range(ns):
        ix = math.floor((slaves[i, 0] - smin[0]) / h)
        iy = math.floor((slaves[i, 1] - smin[1]) / h)
        iz = math.floor((slaves[i, 2] - smin[2]) / h)
        keys[i] = (ix * ny + iy) * nz + iz
    order, skeys = _sort_keys(keys)
    sx = np.empty((ns, 3))
    for k in range(ns):
        for d in range(3):
            sx[k, d] = slaves[order[k], d]
    dense, colstart = _column_table(skeys, nx * ny, nz, ns)  # columns (ix, iy)
    cap = max(16, 4 * (ns + nm))
    buf_k = np.empty(cap, dtype=np.int64)
    buf_m = np.empty(cap, dtype=np.int64)
    npairs = 0
    for j in range(nm):
        l0 = max(lo[j, 0], smin[0])
        u0 = min(hi[j, 0], smax[0])
        l1 = max(lo[j, 1], smin[1])
        u1 = min(hi[j, 1], smax[1])
        l2 = max(lo[j, 2], smin[2])
        u2 = min(hi[j, 2], smax[2])
        if l0 > u0 or l1 > u1 or l2 > u2:
            continue
        ix0 = math.floor((l0 - smin[0]) / h)
        ix1 = math.floor((u0 - smin[0]) / h)
        iy0 = math.floor((l1 - smin[1]) / h)
        iy1 = math.floor((u1 - smin[1]) / h)
        iz0 = math.floor((l2 - smin[2]) / h)
        iz1 = math.floor((u2 - smin[2]) / h)
        for ix in range(ix0, ix1 + 1):
            for iy in range(iy0, iy1 + 1):
                k0, k1 = _column_range(skeys, dense, colstart, ix * ny + iy, nz, iz0, iz1, ns)
                buf_k, buf_m = _reserve(buf_k, buf_m, npairs, k1 - k0)
                for k in range(k0, k1):
                    buf_k[npairs] = k
                    buf_m[npairs] = j
                    npairs += ((lo[j, 0] <= sx[k, 0]) & (sx[k, 0] <= hi[j, 0]) & (lo[j, 1] <= sx[k, 1])
                               & (sx[k, 1] <= hi[j, 1]) & (lo[j, 2] <= sx[k, 2]) & (sx[k, 2] <= hi[j, 2]))
    # faces were visited in increasing order: each slave's list stays sorted
    return _pairs_by_slave(order, buf_k, buf_m, npairs, ns)


def face_boxes(x: np.ndarray, faces: np.ndarray, margin) -> tuple[np.ndarray, np.ndarray]:
    """(lo, hi), each (m, 3): the bounding boxes of the faces (m, k) of the points x (n, 3),
    inflated by ``margin`` (a number, or one per face)."""
    pts = x[faces]
    margin = np.asarray(margin, dtype=float).reshape(-1, 1)
    return pts.min(axis=1) - margin, pts.max(axis=1) + margin


def broad_phase_boxes(slaves: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Candidate pairs (k, 2) [slave, face], unique and sorted by slave then face: every slave
    ``slaves[i]`` (ns, 3) inside the closed box ``lo[j] ≤ x ≤ hi[j]`` (nm, 3) of face j."""
    slaves = np.ascontiguousarray(slaves, dtype=float)
    lo = np.ascontiguousarray(lo, dtype=float)
    hi = np.ascontiguousarray(hi, dtype=float)
    if slaves.ndim != 2 or slaves.shape[1] != 3 or lo.shape != hi.shape or lo.ndim != 2 or lo.shape[1] != 3:
        raise ValueError(f"broad_phase_boxes: slaves (n, 3) and boxes (m, 3) expected, got {slaves.shape}, "
                         f"{lo.shape}, {hi.shape}")
    if not (np.all(np.isfinite(slaves)) and np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
        raise ValueError("broad_phase_boxes: coordinates must be finite")
    return _broad_phase_kernel(slaves, lo, hi)
