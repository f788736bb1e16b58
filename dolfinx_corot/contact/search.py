r"""Contact search for 2D node-to-segment contact: broad phase and narrow phase.

Pure numpy + numba; nothing here knows about DOLFINx.  The master surface is a
set of straight segments given by their end points ``seg_a[j]``, ``seg_b[j]``
(current configuration); the slave surface is a set of points ``slaves[i]``.
The search is split, as usual, into

1. a *broad phase* (global / spatial search) that returns candidate pairs
   (slave, segment) whose slave lies in the segment's axis-aligned bounding box
   inflated by a margin, and
2. a *narrow phase* (local search) that picks for each slave the segment with
   the closest point (closest-point projection, with a deterministic rule for
   ties at shared vertices), optionally refined by walking along neighbouring
   segments.

The broad phase is a bucket (cell) search on a uniform grid whose occupied
cells are addressed through sorted integer cell keys, in the spirit of the
bucket sort of Benson & Hallquist (1990) and the NBS algorithm of Munjiza &
Andrews (1998): the slaves are binned into the one cell containing them and
sorted by cell key (column-major, radix sort, O(ns)); every segment enumerates
the columns of cells its inflated box overlaps and reads the slaves of each
column's row range with two binary searches (inside the column, through a
column table, unless the grid has more than ``4 ns + 64`` columns).  A segment
spanning several cells is thus found from every one of them, and since each
slave sits in exactly one cell no pair is produced twice.  With the cell size
``h`` = mean inflated box size (mean of ``max(|bx - ax|, |by - ay|)`` plus
``2 margin``) the number of (segment, column) visits is at most ``2 nm``, so the
work is ``O(ns + nm log ns + slaves tested)``, where the slaves tested are
those in the visited cells -- a small multiple of the number of pairs unless
the slaves are much denser than the master segments (many slaves per cell).
No ``O(ns · nm)`` loop, no dense grid in memory (so a huge extent or very
different segment lengths are harmless: a long segment costs only the columns
it spans), and the pairs come out sorted by a final counting sort on the slave
index.

References
----------
* P. Wriggers, *Computational Contact Mechanics*, 2nd ed., Springer, 2006 —
  contact search (global search followed by local search and closest-point
  projection onto the master segment; node-to-segment contact in 2D).
* V. A. Yastrebov, *Numerical Methods in Contact Mechanics*, ISTE/Wiley,
  2013 — contact detection: all-to-all vs. bucket/grid-based spatial search,
  local detection, treatment of the blind spots and of the ambiguous
  projections at master vertices.
* D. J. Benson, J. O. Hallquist, A single surface contact algorithm for the
  post-buckling analysis of shell structures, CMAME 78 (1990) 141–163.
* A. Munjiza, K. R. F. Andrews, NBS contact detection algorithm for bodies of
  similar size, IJNME 43 (1998) 131–149.

Conventions
-----------
* Coordinates are float64 arrays of shape (n, 2); they must be finite.
* Segment ``j`` is oriented from ``seg_a[j]`` to ``seg_b[j]``; the local
  coordinate ``xi`` of a point's projection is 0 at ``a``, 1 at ``b``
  (unclamped: ``xi < 0`` or ``xi > 1`` means the projection falls outside).
* A degenerate segment (``a == b``) gets ``xi = 0`` and the distance to ``a``.
* Candidate test (exact, closed box):
  ``min(a, b) - margin <= x_s <= max(a, b) + margin`` in both coordinates,
  evaluated exactly with these floating-point operations.
* Narrow-phase order between the candidates of one slave: smaller squared
  distance to the clamped closest point first; on an exact tie the segment with
  ``0 <= xi <= 1`` first; then the lower segment index.  This is a strict total
  order, so the result does not depend on the order of the pairs.
"""
from __future__ import annotations

import math

import numba
import numpy as np

__all__ = [
    "broad_phase",
    "closest_point",
    "narrow_phase",
    "segment_neighbours_from_cells",
]

_MAX_CELLS_PER_AXIS = float(2**30)  # keeps cell keys ix * NY + iy below 2**61


# --------------------------------------------------------------------------- #
# numba kernels
# --------------------------------------------------------------------------- #
@numba.njit(cache=True)
def _lower_bound(keys, lo, hi, value):
    """First index k in [lo, hi) with keys[k] >= value (hi if none; keys sorted)."""
    while lo < hi:
        mid = (lo + hi) >> 1
        if keys[mid] < value:
            lo = mid + 1
        else:
            hi = mid
    return lo


@numba.njit(cache=True)
def _sort_keys(keys):
    """Stable sort of int64 keys: (permutation, sorted keys).

    LSD radix sort with 11-bit digits, O(n · bits / 11) -- hand-written rather
    than ``np.argsort`` to keep the numba compile short.  ``keys`` is used as
    work space (overwritten).
    """
    n = keys.shape[0]
    order = np.arange(n)
    if n < 2:
        return order, keys
    kmin = keys[0]
    kmax = keys[0]
    for i in range(1, n):
        kmin = min(kmin, keys[i])
        kmax = max(kmax, keys[i])
    span = kmax - kmin
    ks = keys
    for i in range(n):
        ks[i] = ks[i] - kmin
    tmp = np.empty(n, dtype=np.int64)
    tks = np.empty(n, dtype=np.int64)
    cnt = np.empty(2049, dtype=np.int64)
    shift = 0
    while (span >> shift) > 0:
        for d in range(2049):
            cnt[d] = 0
        for i in range(n):
            cnt[((ks[i] >> shift) & 2047) + 1] += 1
        for d in range(2048):
            cnt[d + 1] += cnt[d]
        for i in range(n):
            d = (ks[i] >> shift) & 2047
            q = cnt[d]
            cnt[d] = q + 1
            tmp[q] = order[i]
            tks[q] = ks[i]
        order, tmp = tmp, order
        ks, tks = tks, ks
        shift += 11
    for i in range(n):
        ks[i] = ks[i] + kmin
    return order, ks


@numba.njit(cache=True)
def _column_table(skeys, ncol, stride, ns):
    """(dense, colstart): the start in sorted order of each column of cell keys ``col · stride + i``
    when the table is affordable (ncol ≤ 4 ns + 64); otherwise columns are found by binary
    search over all slaves (dense False, an empty table)."""
    dense = ncol <= 4 * ns + 64
    if not dense:
        return dense, np.empty(0, dtype=np.int64)
    colstart = np.empty(ncol + 1, dtype=np.int64)
    k = 0
    for c in range(ncol + 1):
        while k < ns and skeys[k] < c * stride:
            k += 1
        colstart[c] = k
    return dense, colstart


@numba.njit(cache=True)
def _column_range(skeys, dense, colstart, col, stride, lo, hi, ns):
    """(k0, k1): the sorted positions of the slaves of column ``col`` in cells lo … hi."""
    c0 = colstart[col] if dense else 0
    c1 = colstart[col + 1] if dense else ns
    k0 = _lower_bound(skeys, c0, c1, col * stride + lo)
    return k0, _lower_bound(skeys, k0, c1, col * stride + hi + 1)


@numba.njit(cache=True)
def _reserve(buf_k, buf_m, npairs, extra):
    """The pair buffers, grown (doubled at least) when ``extra`` more pairs would not fit."""
    if npairs + extra <= buf_k.shape[0]:
        return buf_k, buf_m
    cap = max(2 * buf_k.shape[0], npairs + extra)
    nb_k = np.empty(cap, dtype=np.int64)
    nb_m = np.empty(cap, dtype=np.int64)
    nb_k[:npairs] = buf_k[:npairs]
    nb_m[:npairs] = buf_m[:npairs]
    return nb_k, nb_m


@numba.njit(cache=True)
def _pairs_by_slave(order, buf_k, buf_m, npairs, ns):
    """(npairs, 2) [slave, master] from the buffers (slave positions in sorted order, masters
    produced in increasing order), by a counting sort on the slave: lexicographic."""
    count = np.zeros(ns + 1, dtype=np.int64)
    for p in range(npairs):
        count[order[buf_k[p]] + 1] += 1
    for i in range(ns):
        count[i + 1] += count[i]
    pairs = np.empty((npairs, 2), dtype=np.int64)
    for p in range(npairs):
        s = order[buf_k[p]]
        q = count[s]
        count[s] = q + 1
        pairs[q, 0] = s
        pairs[q, 1] = buf_m[p]
    return pairs


@numba.njit(cache=True)
def _broad_phase_kernel(slaves, seg_a, seg_b, margin):
    ns = slaves.shape[0]
    nm = seg_a.shape[0]
    if ns == 0 or nm == 0:
        return np.empty((0, 2), dtype=np.int64)

    # cell size: mean inflated box size
    size_sum = 0.0
    for j in range(nm):
        wx = abs(seg_b[j, 0] - seg_a[j, 0])
        wy = abs(seg_b[j, 1] - seg_a[j, 1])
        size_sum += max(wx, wy)
    h = size_sum / nm + 2.0 * margin

    # grid over the slaves' bounding box
    xmin = slaves[0, 0]
    xmax = slaves[0, 0]
    ymin = slaves[0, 1]
    ymax = slaves[0, 1]
    for i in range(1, ns):
        x = slaves[i, 0]
        y = slaves[i, 1]
        if x < xmin:
            xmin = x
        if x > xmax:
            xmax = x
        if y < ymin:
            ymin = y
        if y > ymax:
            ymax = y
    ext = max(xmax - xmin, ymax - ymin)
    if not h > 0.0:  # all segments are points and margin == 0
        h = ext / ns if ext > 0.0 else 1.0
    if ext / h > _MAX_CELLS_PER_AXIS:
        h = ext / _MAX_CELLS_PER_AXIS
    nx = math.floor((xmax - xmin) / h) + 1
    ny = math.floor((ymax - ymin) / h) + 1

    # bin and sort the slaves by cell key (column-major: ix * ny + iy)
    keys = np.empty(ns, dtype=np.int64)
    for i in range(ns):
        ix = math.floor((slaves[i, 0] - xmin) / h)
        iy = math.floor((slaves[i, 1] - ymin) / h)
        keys[i] = ix * ny + iy
    order, skeys = _sort_keys(keys)
    sxy = np.empty((ns, 2))
    for k in range(ns):
        i = order[k]
        sxy[k, 0] = slaves[i, 0]
        sxy[k, 1] = slaves[i, 1]
    dense, colstart = _column_table(skeys, nx, ny, ns)

    # segments in increasing index: visit the columns of their box; the box
    # test is branch-free (write always, advance the counter when inside)
    cap = max(16, 2 * (ns + nm))
    buf_k = np.empty(cap, dtype=np.int64)  # slave position in sorted order
    buf_m = np.empty(cap, dtype=np.int64)
    npairs = 0
    for j in range(nm):
        ax = seg_a[j, 0]
        ay = seg_a[j, 1]
        bx = seg_b[j, 0]
        by = seg_b[j, 1]
        xlo = min(ax, bx) - margin
        xhi = max(ax, bx) + margin
        ylo = min(ay, by) - margin
        yhi = max(ay, by) + margin
        l0 = max(xlo, xmin)
        u0 = min(xhi, xmax)
        l1 = max(ylo, ymin)
        u1 = min(yhi, ymax)
        if l0 > u0 or l1 > u1:
            continue
        ix0 = math.floor((l0 - xmin) / h)
        ix1 = math.floor((u0 - xmin) / h)
        iy0 = math.floor((l1 - ymin) / h)
        iy1 = math.floor((u1 - ymin) / h)
        for ix in range(ix0, ix1 + 1):
            k0, k1 = _column_range(skeys, dense, colstart, ix, ny, iy0, iy1, ns)
            buf_k, buf_m = _reserve(buf_k, buf_m, npairs, k1 - k0)
            for k in range(k0, k1):
                x = sxy[k, 0]
                y = sxy[k, 1]
                buf_k[npairs] = k
                buf_m[npairs] = j
                npairs += (xlo <= x) & (x <= xhi) & (ylo <= y) & (y <= yhi)

    # segments were produced in increasing order: each slave's list stays sorted
    return _pairs_by_slave(order, buf_k, buf_m, npairs, ns)


@numba.njit(cache=True)
def _project(px, py, ax, ay, bx, by):
    """(xi unclamped, squared distance to the clamped closest point)."""
    dx = bx - ax
    dy = by - ay
    l2 = dx * dx + dy * dy
    if l2 > 0.0:
        xi = ((px - ax) * dx + (py - ay) * dy) / l2
    else:
        xi = 0.0
    if xi <= 0.0:
        cx = ax
        cy = ay
    elif xi >= 1.0:  # the end point itself, so that ties at vertices are exact
        cx = bx
        cy = by
    else:
        cx = ax + xi * dx
        cy = ay + xi * dy
    ex = px - cx
    ey = py - cy
    return xi, ex * ex + ey * ey


@numba.njit(cache=True)
def _better(d2, xi, m, best_d2, best_xi, best_m):
    """Strict total order of the narrow phase: is (d2, xi, m) before the best?"""
    if best_m < 0:
        return True
    if d2 < best_d2:
        return True
    if d2 > best_d2:
        return False
    inside = 0.0 <= xi and xi <= 1.0
    best_inside = 0.0 <= best_xi and best_xi <= 1.0
    if inside != best_inside:
        return inside
    return m < best_m


@numba.njit(cache=True)
def _closest_point_kernel(slaves, seg_a, seg_b, pairs):
    k = pairs.shape[0]
    xi = np.empty(k)
    d2 = np.empty(k)
    for p in range(k):
        s = pairs[p, 0]
        m = pairs[p, 1]
        xi[p], d2[p] = _project(
            slaves[s, 0], slaves[s, 1], seg_a[m, 0], seg_a[m, 1], seg_b[m, 0], seg_b[m, 1]
        )
    return xi, d2


@numba.njit(cache=True)
def _narrow_phase_kernel(slaves, seg_a, seg_b, pairs, neighbours, walk):
    ns = slaves.shape[0]
    nm = seg_a.shape[0]
    best = np.full(ns, -1, dtype=np.int64)
    best_xi = np.full(ns, np.nan)
    best_d2 = np.full(ns, np.inf)
    for p in range(pairs.shape[0]):
        s = pairs[p, 0]
        m = pairs[p, 1]
        xi, d2 = _project(
            slaves[s, 0], slaves[s, 1], seg_a[m, 0], seg_a[m, 1], seg_b[m, 0], seg_b[m, 1]
        )
        if _better(d2, xi, m, best_d2[s], best_xi[s], best[s]):
            best[s] = m
            best_xi[s] = xi
            best_d2[s] = d2
    if walk:
        # local search: move to a neighbouring segment while that is strictly
        # better in the total order (terminates: the order is strict)
        for s in range(ns):
            m = best[s]
            if m < 0:
                continue
            px = slaves[s, 0]
            py = slaves[s, 1]
            for _ in range(nm):
                cur = m
                cxi = best_xi[s]
                cd2 = best_d2[s]
                for e in range(2):
                    n = neighbours[m, e]
                    if n < 0:
                        continue
                    xi, d2 = _project(px, py, seg_a[n, 0], seg_a[n, 1], seg_b[n, 0], seg_b[n, 1])
                    if _better(d2, xi, n, cd2, cxi, cur):
                        cur = n
                        cxi = xi
                        cd2 = d2
                if cur == m:
                    break
                m = cur
                best[s] = cur
                best_xi[s] = cxi
                best_d2[s] = cd2
    return best, best_xi


# --------------------------------------------------------------------------- #
# public API
# --------------------------------------------------------------------------- #
def _points(name: str, x) -> np.ndarray:
    a = np.ascontiguousarray(x, dtype=np.float64)
    if a.size == 0:
        a = a.reshape(0, 2)
    if a.ndim != 2 or a.shape[1] != 2:
        raise ValueError(f"{name} must have shape (n, 2), got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} has non-finite coordinates")
    return a


def _segments(seg_a, seg_b) -> tuple[np.ndarray, np.ndarray]:
    a = _points("seg_a", seg_a)
    b = _points("seg_b", seg_b)
    if a.shape != b.shape:
        raise ValueError(f"seg_a and seg_b differ in shape: {a.shape} vs {b.shape}")
    return a, b


def _pairs(pairs, ns: int, nm: int) -> np.ndarray:
    p = np.ascontiguousarray(pairs, dtype=np.int64)
    if p.size == 0:
        p = p.reshape(0, 2)
    if p.ndim != 2 or p.shape[1] != 2:
        raise ValueError(f"pairs must have shape (k, 2), got {p.shape}")
    if p.shape[0] and (
        p[:, 0].min() < 0 or p[:, 0].max() >= ns or p[:, 1].min() < 0 or p[:, 1].max() >= nm
    ):
        raise ValueError("pairs refer to slaves or segments out of range")
    return p


def broad_phase(
    slaves: np.ndarray, seg_a: np.ndarray, seg_b: np.ndarray, margin: float
) -> np.ndarray:
    """Candidate (slave, segment) pairs: slaves inside the segments' inflated bounding boxes.

    Parameters
    ----------
    slaves : (ns, 2) float
        Slave points.
    seg_a, seg_b : (nm, 2) float
        End points of the master segments.
    margin : float
        Inflation (>= 0) of each segment's axis-aligned bounding box on all
        four sides.  Pair (i, j) is a candidate iff
        ``min(a_j, b_j) - margin <= x_i <= max(a_j, b_j) + margin`` in x and y.
        Every slave whose (Euclidean) distance to segment j is at most
        ``margin`` is a candidate of j (up to rounding of the box bounds).

    Returns
    -------
    pairs : (k, 2) int64
        ``[slave index, segment index]`` rows, unique and sorted
        lexicographically (by slave, then segment).

    Notes
    -----
    Uniform-grid bucket search with sorted cell keys (cell size = mean
    inflated box size, see the module docstring); ``O(ns + nm log ns + k)``
    when the slaves are not much denser than the master segments, memory
    ``O(ns + nm + k)``.
    """
    x = _points("slaves", slaves)
    a, b = _segments(seg_a, seg_b)
    margin = float(margin)
    if not (margin >= 0.0 and np.isfinite(margin)):
        raise ValueError(f"margin must be finite and >= 0, got {margin}")
    return _broad_phase_kernel(x, a, b, margin)


def closest_point(
    slaves: np.ndarray, seg_a: np.ndarray, seg_b: np.ndarray, pairs: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Closest-point projection of the slave onto the segment of each pair.

    Parameters
    ----------
    slaves : (ns, 2) float
    seg_a, seg_b : (nm, 2) float
    pairs : (k, 2) int
        ``[slave index, segment index]`` rows (e.g. from :func:`broad_phase`).

    Returns
    -------
    xi : (k,) float64
        Unclamped local coordinate ``(x_s - a)·(b - a) / |b - a|²`` of the
        projection onto the segment's line (0 at ``a``, 1 at ``b``; 0 for a
        degenerate segment).
    dist2 : (k,) float64
        Squared distance from the slave to the closest point of the segment,
        i.e. the projection clamped to ``xi ∈ [0, 1]`` (the end point itself
        when ``xi`` is outside).
    """
    x = _points("slaves", slaves)
    a, b = _segments(seg_a, seg_b)
    p = _pairs(pairs, x.shape[0], a.shape[0])
    return _closest_point_kernel(x, a, b, p)


def narrow_phase(
    slaves: np.ndarray,
    seg_a: np.ndarray,
    seg_b: np.ndarray,
    pairs: np.ndarray,
    segment_neighbours: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Master segment and local coordinate of every slave.

    Among the candidates of a slave the segment with the smallest distance to
    its clamped closest point wins; exact ties (a slave at a vertex shared by
    two segments, or outside a convex corner) go to the segment whose ``xi``
    lies in ``[0, 1]``, then to the lower segment index.  The result does not
    depend on the order of ``pairs``.

    Parameters
    ----------
    slaves : (ns, 2) float
    seg_a, seg_b : (nm, 2) float
    pairs : (k, 2) int
        Candidate ``[slave, segment]`` rows (any order, e.g. from
        :func:`broad_phase`).
    segment_neighbours : (nm, 2) int, optional
        ``[segment sharing end a, segment sharing end b]`` of each segment,
        -1 at a free end (see :func:`segment_neighbours_from_cells`).  When
        given, each slave's choice is refined by a local walk: move to a
        neighbouring segment as long as it comes strictly earlier in the order
        above.  This ends in a local minimum of the distance along the chain
        of segments and recovers the right segment when the candidate list is
        incomplete (e.g. pairs from an earlier configuration, too small a
        margin) as long as the distance along the chain is unimodal (e.g. a
        slave near a convex or gently curved master).  Slaves without any
        candidate are not walked.

    Returns
    -------
    segment : (ns,) int64
        Chosen master segment, -1 for a slave without candidates.
    xi : (ns,) float64
        Unclamped local coordinate of the projection onto that segment (NaN
        where ``segment == -1``); ``xi`` outside ``[0, 1]`` means the closest
        point is an end point (corner) — left to the contact kernel.
    """
    x = _points("slaves", slaves)
    a, b = _segments(seg_a, seg_b)
    nm = a.shape[0]
    p = _pairs(pairs, x.shape[0], nm)
    if segment_neighbours is None:
        nb = np.empty((0, 2), dtype=np.int64)  # not read without the walk
        walk = False
    else:
        nb = np.ascontiguousarray(segment_neighbours, dtype=np.int64)
        if nb.size == 0:
            nb = nb.reshape(0, 2)
        if nb.shape != (nm, 2):
            raise ValueError(f"segment_neighbours must have shape ({nm}, 2), got {nb.shape}")
        if nb.size and (nb.min() < -1 or nb.max() >= nm):
            raise ValueError("segment_neighbours out of range")
        walk = True
    return _narrow_phase_kernel(x, a, b, p, nb, walk)


def segment_neighbours_from_cells(cells: np.ndarray) -> np.ndarray:
    """Neighbour table for :func:`narrow_phase` from segment connectivity.

    Parameters
    ----------
    cells : (nm, 2) int
        Vertex indices ``[a, b]`` of each segment.

    Returns
    -------
    neighbours : (nm, 2) int64
        ``neighbours[j, e]`` is the other segment incident to vertex
        ``cells[j, e]`` when exactly two segments meet there, -1 otherwise
        (free end or non-manifold vertex).  Orientation need not be consistent.
    """
    c = np.ascontiguousarray(cells, dtype=np.int64)
    if c.size == 0:
        c = c.reshape(0, 2)
    if c.ndim != 2 or c.shape[1] != 2:
        raise ValueError(f"cells must have shape (nm, 2), got {c.shape}")
    nm = c.shape[0]
    out = np.full((nm, 2), -1, dtype=np.int64)
    if nm == 0:
        return out
    vert = c.ravel()  # entry 2j + e is end e of segment j
    order = np.argsort(vert, kind="stable")
    sv = vert[order]
    start = np.flatnonzero(np.r_[True, sv[1:] != sv[:-1]])
    size = np.diff(np.r_[start, sv.size])
    two = start[size == 2]
    e0, e1 = order[two], order[two + 1]
    flat = out.reshape(-1)  # a view
    flat[e0] = e1 // 2
    flat[e1] = e0 // 2
    return out
