"""2D node-to-segment contact search: broad phase vs brute force, projections, narrow phase."""
import numpy as np
import pytest

from dolfinx_corot.contact.search import (
    broad_phase,
    closest_point,
    narrow_phase,
    segment_neighbours_from_cells,
)


# --------------------------------------------------------------------------- #
# helpers
# --------------------------------------------------------------------------- #
def brute_force_pairs(slaves, seg_a, seg_b, margin):
    """O(ns·nm) reference with exactly the documented box test."""
    slaves = np.asarray(slaves, dtype=float).reshape(-1, 2)
    seg_a = np.asarray(seg_a, dtype=float).reshape(-1, 2)
    seg_b = np.asarray(seg_b, dtype=float).reshape(-1, 2)
    lo = np.minimum(seg_a, seg_b) - margin
    hi = np.maximum(seg_a, seg_b) + margin
    inside = np.all((slaves[:, None, :] >= lo[None]) & (slaves[:, None, :] <= hi[None]), axis=2)
    return np.argwhere(inside).astype(np.int64)  # lexicographic (row-major)


def brute_force_narrow(slaves, seg_a, seg_b, pairs):
    """Reference narrow phase: per slave, lexicographic min of (d², outside, index)."""
    ns = len(slaves)
    seg = np.full(ns, -1)
    xi_out = np.full(ns, np.nan)
    xi, d2 = closest_point(slaves, seg_a, seg_b, pairs)
    for s in range(ns):  # reference only: a Python loop is fine here
        rows = np.flatnonzero(pairs[:, 0] == s)
        if rows.size == 0:
            continue
        outside = ~((xi[rows] >= 0) & (xi[rows] <= 1))
        best = rows[np.lexsort((pairs[rows, 1], outside, d2[rows]))[0]]
        seg[s] = pairs[best, 1]
        xi_out[s] = xi[best]
    return seg, xi_out


def random_scene(seed, ns=400, nm=300, margin=0.0):
    """Short, medium and very long segments (some axis-aligned) and slaves, some of
    them exactly on segment end points and on inflated box edges."""
    rng = np.random.default_rng(seed)
    n_long, n_mid = 6, 30
    n_short = nm - n_long - n_mid
    a = rng.uniform(0.0, 1.0, (nm, 2))
    length = np.r_[rng.uniform(0.002, 0.03, n_short), rng.uniform(0.05, 0.3, n_mid),
                   rng.uniform(1.0, 3.0, n_long)]
    angle = rng.uniform(0, 2 * np.pi, nm)
    angle[-n_long:-n_long + 2] = [0.0, np.pi / 2]  # horizontal and vertical long ones
    angle[:10] = 0.0  # short horizontal ones: zero-height boxes
    b = a + length[:, None] * np.column_stack([np.cos(angle), np.sin(angle)])
    b[-n_long + 2] = a[-n_long + 2]  # a degenerate (point) segment
    perm = rng.permutation(nm)  # long ones anywhere in the numbering
    a, b = a[perm], b[perm]

    x = rng.uniform(-0.3, 1.3, (ns, 2))
    k = ns // 8
    pick = rng.integers(0, nm, k)
    x[:k] = np.where(rng.random((k, 1)) < 0.5, a[pick], b[pick])  # exactly on end points
    pick = rng.integers(0, nm, k)
    lo = np.minimum(a[pick], b[pick]) - margin
    hi = np.maximum(a[pick], b[pick]) + margin
    x[k:2 * k, 0] = np.where(rng.random(k) < 0.5, lo[:, 0], hi[:, 0])  # on box edges
    x[k:2 * k, 1] = rng.uniform(lo[:, 1], hi[:, 1])
    x[2 * k:2 * k + 5] = x[0]  # duplicated slaves
    return x, a, b


def polygon(n, radius=1.0):
    """Regular n-gon: vertices at angles 2πj/n, segment j from vertex j to vertex j+1."""
    t = 2 * np.pi * np.arange(n) / n
    v = radius * np.column_stack([np.cos(t), np.sin(t)])
    cells = np.column_stack([np.arange(n), (np.arange(n) + 1) % n])
    return v, cells


# --------------------------------------------------------------------------- #
# broad phase
# --------------------------------------------------------------------------- #
@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("margin", [0.0, 0.01, 0.2])
def test_broad_phase_matches_brute_force(seed, margin):
    x, a, b = random_scene(seed, margin=margin)
    pairs = broad_phase(x, a, b, margin)
    ref = brute_force_pairs(x, a, b, margin)
    assert pairs.dtype == np.int64 and pairs.shape[1] == 2
    assert len(ref) > len(x) // 4  # the scenes are not trivially sparse
    np.testing.assert_array_equal(pairs, ref)


@pytest.mark.parametrize(
    "layout",
    ["vertical line", "horizontal line", "one huge segment", "huge extent", "cluster",
     "far away", "anisotropic"],
)
def test_broad_phase_special_layouts(layout):
    rng = np.random.default_rng(7)
    n = 300
    if layout in ("vertical line", "horizontal line"):
        s = np.sort(rng.uniform(0, 1, n + 1))
        a = np.column_stack([np.zeros(n), s[:-1]])
        b = np.column_stack([np.zeros(n), s[1:]])
        x = np.column_stack([rng.normal(scale=1e-3, size=n), rng.uniform(-0.1, 1.1, n)])
        x[::7, 0] = 0.0
        if layout == "horizontal line":
            a, b, x = a[:, ::-1], b[:, ::-1], x[:, ::-1]
        margin = 2e-3
    elif layout == "one huge segment":  # cell size dominated by one segment
        a = rng.uniform(0, 1, (n, 2))
        b = a + rng.normal(scale=0.01, size=(n, 2))
        a[5], b[5] = [-1e6, -3e5], [1e6, 2e5]
        x = rng.uniform(-1, 2, (n, 2))
        margin = 0.005
    elif layout == "huge extent":  # tiny segments, slaves spread over 1e9: cap on cells
        a = rng.uniform(0, 1e9, (n, 2))
        b = a + rng.normal(scale=1e-3, size=(n, 2))
        x = np.r_[rng.uniform(0, 1e9, (n, 2)), a[:50] + 1e-4, b[50:80]]
        margin = 1e-3
    elif layout == "cluster":  # many slaves in one cell
        a = rng.uniform(0, 1, (n, 2))
        b = a + rng.normal(scale=0.02, size=(n, 2))
        x = np.r_[0.5 + rng.normal(scale=1e-4, size=(n, 2)), rng.uniform(0, 1, (n, 2))]
        margin = 0.01
    elif layout == "far away":  # no pair at all
        a = rng.uniform(0, 1, (n, 2))
        b = a + rng.normal(scale=0.02, size=(n, 2))
        x = rng.uniform(10, 11, (n, 2))
        margin = 0.1
    else:  # strongly anisotropic coordinates
        a = rng.uniform(0, 1, (n, 2)) * [1e-3, 1e3]
        b = a + rng.normal(size=(n, 2)) * [1e-5, 1e1]
        x = rng.uniform(0, 1, (2 * n, 2)) * [1e-3, 1e3]
        margin = 1e-5
    pairs = broad_phase(x, a, b, margin)
    np.testing.assert_array_equal(pairs, brute_force_pairs(x, a, b, margin))
    if layout == "far away":
        assert pairs.shape == (0, 2)
    else:
        assert len(pairs) > 0


def test_broad_phase_degenerate_inputs():
    rng = np.random.default_rng(3)
    x = rng.uniform(size=(10, 2))
    a = rng.uniform(size=(6, 2))
    b = a + 0.1
    empty = np.empty((0, 2))
    for args in ((empty, a, b), (x, empty, empty), (empty, empty, empty)):
        pairs = broad_phase(*args, 0.3)
        assert pairs.shape == (0, 2) and pairs.dtype == np.int64
    assert broad_phase([], [], [], 0.0).shape == (0, 2)

    # everything at one point, margin 0: every slave is a candidate of every segment
    p = np.full((7, 2), 0.25)
    pairs = broad_phase(p, p[:5], p[:5], 0.0)
    expected = np.array([[i, j] for i in range(7) for j in range(5)])
    np.testing.assert_array_equal(pairs, expected)

    # point segments, margin 0: only slaves exactly on the point
    pts = np.array([[0.0, 0.0], [1.0, 2.0], [1.0, 2.0], [3.0, -1.0]])
    x = np.array([[1.0, 2.0], [1.0, 2.0 + 1e-15], [3.0, -1.0], [0.0, 0.0], [5.0, 5.0]])
    pairs = broad_phase(x, pts, pts, 0.0)
    np.testing.assert_array_equal(pairs, [[0, 1], [0, 2], [2, 3], [3, 0]])

    # one slave: the grid has one cell
    pairs = broad_phase([[0.5, 0.5]], [[0.0, 0.0], [0.6, 0.6]], [[1.0, 1.0], [2.0, 0.6]], 0.0)
    np.testing.assert_array_equal(pairs, [[0, 0]])


def test_broad_phase_rejects_bad_input():
    x = np.zeros((3, 2))
    with pytest.raises(ValueError):
        broad_phase(x, x, x, -1.0)
    with pytest.raises(ValueError):
        broad_phase(x, x, x, np.nan)
    with pytest.raises(ValueError):
        broad_phase(np.array([[np.nan, 0.0]]), x, x, 0.1)
    with pytest.raises(ValueError):
        broad_phase(np.zeros((3, 3)), x, x, 0.1)
    with pytest.raises(ValueError):
        broad_phase(x, x, x[:2], 0.1)


def test_broad_phase_margin_contains_distance_ball():
    """Every slave within Euclidean distance `margin` of a segment is a candidate of it."""
    rng = np.random.default_rng(11)
    a = rng.uniform(0, 1, (200, 2))
    b = a + rng.normal(scale=0.05, size=(200, 2))
    x = rng.uniform(-0.1, 1.1, (2000, 2))
    margin = 0.03
    pairs = broad_phase(x, a, b, margin)
    all_pairs = np.argwhere(np.ones((len(x), len(a)), bool))
    _, d2 = closest_point(x, a, b, all_pairs)
    near = all_pairs[d2 <= margin**2]
    found = {tuple(p) for p in pairs}
    assert len(near) > 100
    assert all(tuple(p) in found for p in near)


# --------------------------------------------------------------------------- #
# closest point
# --------------------------------------------------------------------------- #
def test_closest_point_hand_values():
    seg_a = np.array([[0.0, 0.0], [1.0, 1.0], [2.0, 2.0]])
    seg_b = np.array([[2.0, 0.0], [3.0, 3.0], [2.0, 2.0]])  # the last one is degenerate
    x = np.array([[1.0, 1.0], [3.0, 1.0], [-1.0, -2.0], [1.0, 3.0], [0.0, 0.0], [2.0, 0.0],
                  [5.0, 6.0]])
    pairs = np.array([[0, 0], [1, 0], [2, 0], [3, 1], [4, 1], [5, 2], [6, 1], [4, 0]])
    xi, d2 = closest_point(x, seg_a, seg_b, pairs)
    np.testing.assert_allclose(xi, [0.5, 1.5, -0.5, 0.5, -0.5, 0.0, 2.25, 0.0], atol=1e-15)
    np.testing.assert_allclose(d2, [1.0, 2.0, 5.0, 2.0, 2.0, 4.0, 13.0, 0.0], atol=1e-15)
    xi, d2 = closest_point(x, seg_a, seg_b, np.empty((0, 2), dtype=np.int64))
    assert xi.shape == (0,) and d2.shape == (0,)
    with pytest.raises(ValueError):
        closest_point(x, seg_a, seg_b, [[0, 3]])


# --------------------------------------------------------------------------- #
# narrow phase
# --------------------------------------------------------------------------- #
N_POLY = 64


@pytest.mark.parametrize("radius, margin", [(0.95, 0.1), (1.2, 0.4)])
def test_narrow_phase_circle(radius, margin):
    """Slaves on a concentric circle pick the segment they are angularly inside.

    Inside the regular polygon that is always the closest segment; outside,
    near a vertex the closest point is the vertex itself, a tie between the two
    neighbours that goes to the lower index (both xi outside [0, 1]).
    """
    v, cells = polygon(N_POLY)
    a, b = v[cells[:, 0]], v[cells[:, 1]]
    rng = np.random.default_rng(5)
    phi = rng.uniform(0, 2 * np.pi, 2000)
    x = radius * np.column_stack([np.cos(phi), np.sin(phi)])
    pairs = broad_phase(x, a, b, margin)
    seg, xi = narrow_phase(x, a, b, pairs)

    dphi = 2 * np.pi / N_POLY
    j = np.floor(phi / dphi).astype(int)
    half = np.sin(np.pi / N_POLY)
    tangential = radius * np.sin(phi - (j + 0.5) * dphi)  # along segment j from its midpoint
    xi_exact = 0.5 + tangential / (2 * half)
    on_segment = np.abs(tangential) <= half
    if radius < 1:
        assert on_segment.all()
    else:
        assert 0.1 < np.mean(~on_segment) < 0.9  # both cases occur
    expected = np.where(on_segment, j, np.where(tangential > 0, np.minimum(j, (j + 1) % N_POLY),
                                                np.minimum(j, (j - 1) % N_POLY)))
    np.testing.assert_array_equal(seg, expected)
    # xi on the angular segment from the exact formula; at vertex ties xi is
    # that of the chosen neighbour (just beyond its end)
    np.testing.assert_allclose(xi[on_segment], xi_exact[on_segment], atol=1e-12)
    assert np.all((xi[~on_segment] < 0) | (xi[~on_segment] > 1))
    np.testing.assert_array_equal(seg, brute_force_narrow(x, a, b, pairs)[0])


def test_narrow_phase_slave_at_vertex_is_deterministic():
    v, cells = polygon(N_POLY)
    a, b = v[cells[:, 0]], v[cells[:, 1]]
    x = v.copy()  # exactly on the vertices
    pairs = broad_phase(x, a, b, 0.05)
    seg, xi = narrow_phase(x, a, b, pairs)
    # both neighbours have distance 0 and xi in [0, 1]: the lower index wins
    expected = np.r_[0, np.arange(N_POLY - 1)]
    np.testing.assert_array_equal(seg, expected)
    np.testing.assert_array_equal(xi, np.r_[0.0, np.ones(N_POLY - 1)])
    rng = np.random.default_rng(0)
    for _ in range(3):  # independent of the order of the pairs
        seg2, xi2 = narrow_phase(x, a, b, pairs[rng.permutation(len(pairs))])
        np.testing.assert_array_equal(seg2, seg)
        np.testing.assert_array_equal(xi2, xi)


def test_narrow_phase_tie_prefers_inside_then_lower_index():
    seg_a = np.array([[1.5, 1.0], [0.0, 0.0], [2.5, 3.0], [3.0, 1.0]])
    seg_b = np.array([[2.5, 1.0], [1.0, 0.0], [3.5, 3.0], [3.0, 1.5]])
    # slave 0: d² = 1 to segment 0 (xi = -1, its end point) and to segment 1
    #          (xi = 0.5, interior): the interior one wins despite its higher index
    # slave 1: d² = 1.25 to the end points of segments 2 (xi = -0.5) and 3
    #          (xi = 2), both outside: the lower index wins
    x = np.array([[0.5, 1.0], [2.0, 2.0]])
    pairs = np.array([[0, 0], [0, 1], [1, 2], [1, 3]])
    xi, d2 = closest_point(x, seg_a, seg_b, pairs)
    np.testing.assert_array_equal(xi, [-1.0, 0.5, -0.5, 2.0])
    np.testing.assert_array_equal(d2, [1.0, 1.0, 1.25, 1.25])
    for p in (pairs, pairs[::-1], pairs[[1, 0, 3, 2]]):
        seg, xi = narrow_phase(x, seg_a, seg_b, p)
        np.testing.assert_array_equal(seg, [1, 2])
        np.testing.assert_array_equal(xi, [0.5, -0.5])


@pytest.mark.parametrize("seed", range(3))
def test_narrow_phase_matches_brute_force(seed):
    x, a, b = random_scene(seed, ns=300, nm=200, margin=0.05)
    pairs = broad_phase(x, a, b, 0.05)
    seg, xi = narrow_phase(x, a, b, pairs)
    seg_ref, xi_ref = brute_force_narrow(x, a, b, pairs)
    np.testing.assert_array_equal(seg, seg_ref)
    np.testing.assert_array_equal(xi, xi_ref)  # NaN where no candidate
    assert (seg == -1).any() and (seg >= 0).any()
    perm = np.random.default_rng(seed).permutation(len(pairs))
    np.testing.assert_array_equal(narrow_phase(x, a, b, pairs[perm])[0], seg)


def test_narrow_phase_without_candidates_and_empty():
    x = np.array([[0.0, 0.0], [5.0, 5.0]])
    a = np.array([[-1.0, 0.1]])
    b = np.array([[1.0, 0.1]])
    seg, xi = narrow_phase(x, a, b, broad_phase(x, a, b, 0.2))
    np.testing.assert_array_equal(seg, [0, -1])
    assert xi[0] == pytest.approx(0.5) and np.isnan(xi[1])
    seg, xi = narrow_phase(np.empty((0, 2)), a, b, np.empty((0, 2), dtype=np.int64))
    assert seg.shape == (0,) and xi.shape == (0,)
    seg, xi = narrow_phase(x, np.empty((0, 2)), np.empty((0, 2)), np.empty((0, 2), int))
    np.testing.assert_array_equal(seg, [-1, -1])
    assert np.isnan(xi).all()


@pytest.mark.parametrize("offset", [5, -7])
def test_narrow_phase_walk_along_neighbours(offset):
    """With a wrong single candidate per slave, the neighbour walk finds the right segment."""
    v, cells = polygon(N_POLY)
    a, b = v[cells[:, 0]], v[cells[:, 1]]
    rng = np.random.default_rng(2)
    phi = rng.uniform(0, 2 * np.pi, 500)
    x = 0.95 * np.column_stack([np.cos(phi), np.sin(phi)])
    right = np.floor(phi / (2 * np.pi / N_POLY)).astype(int)
    wrong = np.column_stack([np.arange(len(x)), (right + offset) % N_POLY])
    seg, _ = narrow_phase(x, a, b, wrong)
    np.testing.assert_array_equal(seg, wrong[:, 1])  # no walk without neighbours
    nb = segment_neighbours_from_cells(cells)
    seg, xi = narrow_phase(x, a, b, wrong, segment_neighbours=nb)
    np.testing.assert_array_equal(seg, right)
    np.testing.assert_array_equal(xi, narrow_phase(x, a, b, broad_phase(x, a, b, 0.1))[1])
    with pytest.raises(ValueError):
        narrow_phase(x, a, b, wrong, segment_neighbours=nb[:-1])


def test_segment_neighbours_from_cells():
    # open polyline 0-1-2-3, one segment reversed
    nb = segment_neighbours_from_cells([[0, 1], [2, 1], [2, 3]])
    np.testing.assert_array_equal(nb, [[-1, 1], [2, 0], [1, -1]])
    # closed loop
    nb = segment_neighbours_from_cells(polygon(5)[1])
    np.testing.assert_array_equal(nb, [[4, 1], [0, 2], [1, 3], [2, 4], [3, 0]])
    # T junction at vertex 1: non-manifold, no neighbour there
    nb = segment_neighbours_from_cells([[0, 1], [1, 2], [1, 3], [3, 4]])
    np.testing.assert_array_equal(nb, [[-1, -1], [-1, -1], [-1, 3], [2, -1]])
    assert segment_neighbours_from_cells(np.empty((0, 2), int)).shape == (0, 2)
