"""octoray's Python package: answers against known values, brute force and trimesh; exactness on
grid meshes; hostile input; threads."""

import numpy as np
import pytest

import octoray

# A tetrahedron with its faces counter-clockwise seen from outside.
TET_V = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
TET_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def grid_cube(n):
    """The cube [0, n]^3 with integer vertices, each face split into 2 n^2 triangles, faces
    outward: every vertex on a coarse grid, the worst case for shared edges."""
    verts, index, faces = [], {}, []

    def vid(p):
        if p not in index:
            index[p] = len(verts)
            verts.append(p)
        return index[p]

    for axis in range(3):
        for side in (0, n):
            a, b = (axis + 1) % 3, (axis + 2) % 3
            for i in range(n):
                for j in range(n):
                    quad = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0, 0, 0]
                        p[axis], p[a], p[b] = side, i + di, j + dj
                        quad.append(vid(tuple(p)))
                    q0, q1, q2, q3 = quad
                    # (a, b, axis) is right-handed: counter-clockwise in (a, b) faces +axis.
                    tris = [(q0, q1, q2), (q0, q2, q3)]
                    if side == 0:
                        tris = [(t[0], t[2], t[1]) for t in tris]
                    faces.extend(tris)
    return np.array(verts, dtype=np.float32), np.array(faces, dtype=np.int64)


def rays_at(origins, directions):
    return np.hstack([np.asarray(origins, np.float32), np.asarray(directions, np.float32)])


def brute_first(v, f, rays):
    """The nearest hit of each ray over every face, one face at a time through octoray itself
    (a one-triangle mesh needs no tree): the BVH must agree bit for bit."""
    t = np.full(len(rays), np.inf, dtype=np.float32)
    prim = np.full(len(rays), -1)
    for k, face in enumerate(f):
        h = octoray.Mesh(v[face], np.array([[0, 1, 2]])).closest(rays, threads=1)
        nearer = h.t < t
        t[nearer], prim[nearer] = h.t[nearer], k
    return t, prim


def test_tetrahedron_known_answers():
    m = octoray.Mesh(TET_V, TET_F)
    assert (m.triangle_count, m.tier, m.is_closed) == (4, "watertight", True)
    h = m.closest(rays_at([[0.1, 0.2, -1], [5, 5, 5]], [[0, 0, 1], [1, 0, 0]]))
    assert h.t[0] == 1.0 and h.prim[0] == 0 and h.front[0]
    np.testing.assert_array_equal(h.normal[0], [0, 0, -1])
    assert h.t[1] == np.inf and h.prim[1] == -1 and not h.hit[1]
    assert m.contains([[0.1, 0.1, 0.1], [0.5, 0.5, 0.5]]).tolist() == [True, False]
    assert m.winding_number([[0.1, 0.1, 0.1], [2, 2, 2]]).tolist() == [1, 0]
    d = m.signed_distance([[0.1, 0.2, 0.3], [0, 0, -2]])
    assert d[0] == np.float32(-0.1) and d[1] == 2.0
    c = m.closest_points([[0.2, 0.3, -5]], max_distance=10)
    np.testing.assert_array_equal(c.point, np.array([[0.2, 0.3, 0]], dtype=np.float32))
    assert c.distance[0] == 5.0 and c.prim[0] == 0
    assert m.closest_points([[0.2, 0.3, -5]], max_distance=4).prim[0] == -1
    a = m.all_hits(rays_at([[0.1, 0.1, -1]], [[0, 0, 1]]))
    assert a.ray.tolist() == [0, 0] and a.prim.tolist() == [0, 3]
    assert a.t.tolist() == sorted(a.t.tolist())


@pytest.mark.parametrize("tier", octoray.TIERS)
def test_bvh_equals_brute_force(tier):
    rng = np.random.default_rng(7)
    v = rng.uniform(-1, 1, (150, 3)).astype(np.float32)
    f = rng.integers(0, len(v), (60, 3))
    rays = rays_at(rng.uniform(-2, 2, (400, 3)), rng.normal(size=(400, 3)))
    m = octoray.Mesh(v, f, tier=tier)
    h = m.closest(rays, threads=1)
    t, prim = brute_first(v, f, rays) if tier == "watertight" else (None, None)
    if t is not None:
        np.testing.assert_array_equal(h.t, t)
        np.testing.assert_array_equal(h.prim, prim)
    assert h.hit.sum() > 20
    np.testing.assert_array_equal(m.occluded(rays), h.hit)
    # Every hit: each face once per ray, and the first of them is the closest hit.
    a = m.all_hits(rays)
    pairs = set(zip(a.ray.tolist(), a.prim.tolist()))
    assert len(pairs) == len(a.ray)
    first = np.searchsorted(a.ray, np.flatnonzero(h.hit))
    np.testing.assert_array_equal(a.t[first], h.t[h.hit])


def test_grid_cube_is_exact_through_vertices_and_edges():
    """Rays from inside points through every vertex, edge midpoint and face centre of a grid
    cube: each leaves it once (odd crossings), and every inside point is contained."""
    n = 4
    v, f = grid_cube(n)
    m = octoray.Mesh(v, f)
    assert m.is_closed
    targets = np.array(
        [(x, y, z) for x in range(n + 1) for y in range(n + 1) for z in range(n + 1)]
        + [(x + 0.5, y, 0) for x in range(n) for y in range(n + 1)],
        dtype=np.float64,
    )
    on_surface = (targets == 0).any(1) | (targets == n).any(1)
    targets = targets[on_surface]
    for inside in ([2, 2, 2], [1, 1, 1], [0.5, 3, 2.25]):
        o = np.broadcast_to(np.array(inside, np.float32), targets.shape)
        rays = rays_at(o, targets - inside)
        assert (m.crossings(rays) % 2 == 1).all()
        assert m.occluded(rays).all()
    pts = np.random.default_rng(3).uniform(-1, n + 1, (5000, 3)).astype(np.float32)
    expected = ((pts > 0) & (pts < n)).all(1)
    on = ((pts == 0) | (pts == n)).any(1)
    np.testing.assert_array_equal(m.contains(pts)[~on], expected[~on])
    # Points on the surface, classified as moved a step along +x, then +y, then +z.
    lattice = targets.astype(np.float32)
    inside = m.contains(lattice)
    moved = lattice + np.float32(1e-3) * np.array([1, 1e-3, 1e-6], dtype=np.float32)
    np.testing.assert_array_equal(inside, ((moved > 0) & (moved < n)).all(1))


def test_hostile_input_raises_or_misses():
    with pytest.raises(ValueError):
        octoray.Mesh(TET_V[:, :2], TET_F)
    with pytest.raises(TypeError):
        octoray.Mesh(TET_V, TET_F.astype(np.float64))
    with pytest.raises(ValueError):
        octoray.Mesh(TET_V, np.array([[0, 1, 4]]))
    with pytest.raises(ValueError):
        octoray.Mesh(TET_V, np.array([[0, 1, -1]]))
    with pytest.raises(ValueError):
        octoray.Mesh(TET_V, TET_F, tier="fast")
    m = octoray.Mesh(TET_V, TET_F)
    with pytest.raises(ValueError):
        m.closest(np.zeros((3, 5)))
    with pytest.raises(ValueError):
        m.closest(np.zeros(6))
    with pytest.raises(ValueError):
        m.closest(np.zeros((3, 6)), t_max=np.ones(2))
    with pytest.raises(ValueError):
        m.closest(np.zeros((3, 6)), threads=0)
    with pytest.raises(ValueError):
        m.contains(np.zeros((2, 4)))
    nan, inf = np.nan, np.inf
    bad = np.array(
        [
            [nan, 0, 0, 0, 0, 1],
            [0.1, 0.1, -1, 0, 0, 0],
            [0.1, 0.1, -1, inf, 0, 1],
            [0.1, 0.1, -1, 0, 0, nan],
            [1e-45, 1e-45, -1, 1e-45, 1e-45, 1e-45],
        ]
    )
    h = m.closest(bad)
    assert (h.prim == -1).all() and np.isinf(h.t).all()
    assert not m.occluded(bad).any()
    assert m.crossings(bad).tolist() == [0] * len(bad)
    assert len(m.all_hits(bad).ray) == 0
    # An empty range, and a reversed one.
    ok = rays_at([[0.1, 0.1, -1]] * 2, [[0, 0, 1]] * 2)
    assert not m.occluded(ok, t_min=[0.5, 2], t_max=[0.5, 1]).any()
    assert m.signed_distance([[nan, 0, 0]])[0] != m.signed_distance([[nan, 0, 0]])[0]
    assert not m.contains([[inf, 0, 0]])[0]
    # Empty batches and an empty mesh.
    assert len(m.closest(np.zeros((0, 6))).t) == 0
    empty = octoray.Mesh(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))
    assert empty.closest(ok).prim.tolist() == [-1, -1]
    # Open meshes refuse the queries that need a closed one.
    opened = octoray.Mesh(TET_V, TET_F[:3])
    assert not opened.is_closed
    for query in (opened.contains, opened.winding_number, opened.signed_distance):
        with pytest.raises(ValueError, match="not closed"):
            query([[0.1, 0.1, 0.1]])
    # The generalized winding number takes open meshes; a bad tolerance raises.
    with pytest.raises(ValueError, match="tolerance"):
        opened.generalized_winding_number([[0.1, 0.1, 0.1]], tolerance=-1)
    with pytest.raises(ValueError, match="tolerance"):
        opened.generalized_winding_number([[0.1, 0.1, 0.1]], tolerance=nan)
    assert np.isnan(opened.generalized_winding_number([[nan, 0, 0]])[0])
    # Degenerate and subnormal faces: misses, never NaN.
    flat = octoray.Mesh(
        np.array([[0, 0, 0], [1, 1, 1], [2, 2, 2], [1e-45, 0, 0], [0, 1e-45, 0]]),
        np.array([[0, 1, 2], [0, 3, 4]]),
    )
    h = flat.closest(rays_at(np.random.default_rng(1).normal(size=(64, 3)), np.ones((64, 3))))
    assert not np.isnan(h.t).any()


def test_threads_give_the_same_bits():
    v, f = grid_cube(6)
    m = octoray.Mesh(v, f)
    rng = np.random.default_rng(11)
    rays = rays_at(rng.uniform(-2, 8, (20000, 3)), rng.normal(size=(20000, 3)))
    one, many = m.closest(rays, threads=1), m.closest(rays, threads=4)
    for a, b in zip((one.t, one.prim, one.u, one.v, one.normal), (many.t, many.prim, many.u, many.v, many.normal)):
        assert a.tobytes() == b.tobytes()
    pts = rng.uniform(-1, 7, (5000, 3))
    assert m.signed_distance(pts, threads=1).tobytes() == m.signed_distance(pts).tobytes()
    a1, a4 = m.all_hits(rays, threads=1), m.all_hits(rays, threads=3)
    assert a1.ray.tobytes() == a4.ray.tobytes() and a1.t.tobytes() == a4.t.tobytes()


def test_generalized_winding_number_on_closed_and_open_meshes():
    v, f = grid_cube(4)
    m = octoray.Mesh(v, f)
    rng = np.random.default_rng(5)
    # An eighth of a cell off the grid: never on the surface.
    p = rng.integers(-2, 7, (500, 3)) + 0.125
    exact = m.winding_number(p)
    for tol in (0.0, 1e-3, 0.1):
        w = m.generalized_winding_number(p, tolerance=tol)
        assert w.dtype == np.float64 and np.abs(w - exact).max() <= tol + 1e-9
    # On the surface: a half. Threads: the same bits.
    assert abs(m.generalized_winding_number([[2, 2, 0]])[0] - 0.5) < 1e-3 + 1e-9
    a = m.generalized_winding_number(p, threads=1)
    assert a.tobytes() == m.generalized_winding_number(p, threads=3).tobytes()
    # The tetrahedron without its face at z = 0: the face's share is missing, by the solid angle
    # it subtends (from a point above its centroid, analytically by Van Oosterom-Strackee).
    opened = octoray.Mesh(TET_V, TET_F[1:])
    q = np.array([1 / 3, 1 / 3, 0.1])
    a, b, c = TET_V[0] - q, TET_V[2] - q, TET_V[1] - q
    la, lb, lc = (np.linalg.norm(x) for x in (a, b, c))
    cap = 2 * np.arctan2(a @ np.cross(b, c), la * lb * lc + (a @ b) * lc + (a @ c) * lb + (b @ c) * la)
    w = opened.generalized_winding_number([q], tolerance=0)[0]
    assert abs(w - (1 - cap / (4 * np.pi))) < 1e-6


def test_nearest_within_equals_brute_force():
    """The k nearest faces within a radius: each face's distance is what the one-face mesh's
    closest point reports, bit for bit; the rows are the brute-force order (distance, then
    face); `complete` says whether the row holds every face within the radius."""
    rng = np.random.default_rng(11)
    v = rng.uniform(-1, 1, (90, 3)).astype(np.float32)
    f = rng.integers(0, len(v), (40, 3))
    # Faces 30..39 repeat faces 0..9: equal distances, ordered by face index.
    f[30:] = f[:10]
    pts = rng.uniform(-1.5, 1.5, (64, 3)).astype(np.float32)
    m = octoray.Mesh(v, f)
    one = np.stack([octoray.Mesh(v, f[j : j + 1]).closest_points(pts).distance for j in range(len(f))], axis=1)
    for k, radius in [(1, np.inf), (5, 0.6), (12, 0.3), (40, np.inf), (0, 1.0)]:
        got = m.nearest_within(pts, k, radius)
        assert got.distance.shape == got.prim.shape == (len(pts), k)
        for i in range(len(pts)):
            order = sorted((d, j) for j, d in enumerate(one[i].tolist()) if d <= radius)
            want = order[:k]
            assert got.prim[i, : len(want)].tolist() == [j for _, j in want]
            np.testing.assert_array_equal(got.distance[i, : len(want)], np.array([d for d, _ in want], dtype=np.float32))
            assert (got.prim[i, len(want) :] == -1).all() and np.isinf(got.distance[i, len(want) :]).all()
            assert got.complete[i] == (len(order) < k or not order)
    with pytest.raises(ValueError, match="k must be"):
        m.nearest_within(pts, 41)
    with pytest.raises(ValueError, match="radius"):
        m.nearest_within(pts, 3, radius=-1.0)
    with pytest.raises(ValueError, match="radius"):
        m.nearest_within(pts, 3, radius=np.nan)
