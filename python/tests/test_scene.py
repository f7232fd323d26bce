"""octoray.Scene: meshes and spheres placed by instances, masks, world normals; against one-mesh
answers and known values; hostile input."""

import numpy as np
import pytest

import octoray
from octoray import _octoray

QUAD_V = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], dtype=np.float32)
QUAD_F = np.array([[0, 1, 2], [0, 2, 3]])


def rays_at(origins, directions):
    return np.hstack([np.asarray(origins, np.float32), np.asarray(directions, np.float32)])


def translation(x, y, z):
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def rotation_scale(angle, axis, scale):
    """Rotation by ``angle`` about a coordinate axis times a (per-axis) scale, as 4x4."""
    c, s = np.cos(angle), np.sin(angle)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    r = np.eye(3)
    r[i, i], r[i, j], r[j, i], r[j, j] = c, -s, s, c
    m = np.eye(4)
    m[:3, :3] = r @ np.diag(scale)
    return m


def test_walls_and_a_ball_with_masks():
    s = octoray.Scene()
    wall = s.add_mesh(QUAD_V, QUAD_F)
    ball = s.add_spheres([[0, 0, 0]], 0.5)
    far = translation(0, 0, 5)
    assert s.add_instance(wall, mask=1) == 0
    assert s.add_instance([wall], far, mask=1) == 1
    assert s.add_instance(ball, far, mask=2) == 2
    r = rays_at([[0.25, 0.1, 10]], [[0, 0, -1]])
    h = s.closest(r)
    assert (h.geom[0], h.inst[0]) == (ball, 2) and 4.5 < h.t[0] < 5.0
    # The sphere's outward normal at the hit point, facing the ray.
    p = r[0, :3] + h.t[0] * r[0, 3:] - [0, 0, 5]
    np.testing.assert_allclose(h.normal[0], p / np.linalg.norm(p), atol=1e-6)
    assert h.front[0]
    h = s.closest(r, mask=1)
    assert (h.t[0], h.geom[0], h.inst[0], h.prim[0] >= 0) == (5.0, wall, 1, True)
    np.testing.assert_array_equal(h.normal[0], [0, 0, 1])
    # One mask per ray; a mask that sees nothing.
    both = np.vstack([r, r, r])
    h = s.closest(both, mask=np.array([2, 1, 4], dtype=np.uint32))
    assert h.inst.tolist() == [2, 1, -1]
    assert s.occluded(both, mask=[2, 1, 4]).tolist() == [True, True, False]


def test_identity_instance_equals_the_mesh():
    rng = np.random.default_rng(4)
    v = rng.uniform(-1, 1, (200, 3)).astype(np.float32)
    f = rng.integers(0, 200, (300, 3))
    rays = rays_at(rng.uniform(-2, 2, (3000, 3)), rng.normal(size=(3000, 3)))
    for tier in octoray.TIERS:
        s = octoray.Scene(tier)
        s.add_instance(s.add_mesh(v, f))
        a, b = s.closest(rays), octoray.Mesh(v, f, tier).closest(rays)
        assert a.t.tobytes() == b.t.tobytes() and a.prim.tobytes() == b.prim.tobytes()
        assert a.u.tobytes() == b.u.tobytes() and a.normal.tobytes() == b.normal.tobytes()
        assert (a.geom[a.hit] == 0).all() and (a.inst[a.hit] == 0).all()
        np.testing.assert_array_equal(s.occluded(rays), b.hit)


def test_placed_instances_agree_with_placed_vertices():
    """Instances moved, rotated, scaled and mirrored against meshes built from the placed
    vertices: the same faces hit (away from edges) at nearly the same t, normals equal to the
    cross products of the placed vertices."""
    rng = np.random.default_rng(8)
    v = rng.uniform(-1, 1, (60, 3)).astype(np.float32)
    f = rng.integers(0, 60, (40, 3))
    places = [
        translation(3, 0, 0),
        translation(-3, 1, 0) @ rotation_scale(0.7, 1, (1, 1, 1)),
        translation(0, 3, 1) @ rotation_scale(1.1, 0, (2, 0.5, 1)),
        translation(0, -3, -1) @ rotation_scale(0.3, 2, (-1, 1, 1)),  # mirrored
    ]
    s = octoray.Scene()
    g = s.add_mesh(v, f)
    for m in places:
        s.add_instance(g, m)
    # From anywhere around, aimed near one of the instances.
    origins = rng.uniform(-8, 8, (4000, 3))
    aims = np.array([m[:3, 3] for m in places])[rng.integers(0, len(places), 4000)]
    rays = rays_at(origins, aims + rng.uniform(-1.5, 1.5, (4000, 3)) - origins)
    h = s.closest(rays)
    best_t = np.full(len(rays), np.inf)
    best = np.full((len(rays), 2), -1)
    for k, m in enumerate(places):
        w = (np.c_[v, np.ones(len(v))] @ m.T)[:, :3]
        e = octoray.Mesh(w, f).closest(rays)
        nearer = e.t < best_t
        best_t[nearer], best[nearer] = e.t[nearer], np.c_[np.full(nearer.sum(), k), e.prim[nearer]]
    clear = np.isfinite(best_t) == h.hit
    assert clear.mean() > 0.995 and h.hit.sum() > 1000
    both = h.hit & np.isfinite(best_t)
    same = (h.inst[both] == best[both, 0]) & (h.prim[both] == best[both, 1])
    assert same.mean() > 0.99
    np.testing.assert_allclose(h.t[both][same], best_t[both][same], rtol=1e-4, atol=1e-5)
    # World normals: the placed face's (v1 - v0) x (v2 - v0), unit length.
    idx = np.flatnonzero(both)[same]
    for i in idx[:200]:
        m = places[h.inst[i]]
        w = (np.c_[v[f[h.prim[i]]], np.ones(3)] @ m.T)[:, :3]
        n = np.cross(w[1] - w[0], w[2] - w[0])
        np.testing.assert_allclose(h.normal[i], n / np.linalg.norm(n), atol=1e-4)
        assert h.front[i] == (np.dot(n, rays[i, 3:]) <= 0)


def test_hostile_scene_input():
    s = octoray.Scene()
    g = s.add_mesh(QUAD_V, QUAD_F)
    b = s.add_spheres([[0, 0, 0]], [1.0])
    for bad in ([], [7], [g, b], [-1]):
        with pytest.raises(ValueError):
            s.add_instance(bad)
    with pytest.raises(TypeError):
        s.add_instance([0.5])
    singular = np.eye(4)
    singular[2, 2] = 0
    nan = np.eye(4)
    nan[0, 3] = np.nan
    projective = np.eye(4)
    projective[3, 0] = 1
    for m in (singular, nan, projective, np.eye(3)):
        with pytest.raises(ValueError):
            s.add_instance(g, m)
    with pytest.raises(ValueError):
        s.add_instance(g, mask=-1)
    with pytest.raises(ValueError):
        s.add_spheres([[0, 0, 0], [1, 1, 1]], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError):
        octoray.Scene("fast")
    s.add_instance(g)
    r = rays_at([[0, 0, 5]], [[0, 0, -1]])
    with pytest.raises(ValueError):
        s.closest(r, mask=[1, 2])
    with pytest.raises(TypeError):
        s.closest(r, mask=1.5)
    # Commits itself before a query; the native class refuses an uncommitted scene.
    assert s.closest(r).t[0] == 5.0
    raw = _octoray.Scene("watertight")
    raw.add_instance([raw.add_mesh(QUAD_V, QUAD_F)], [1.0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0], 1)
    one = np.ones(1, np.float32)
    with pytest.raises(RuntimeError):
        raw.closest(r, one * 0, one * np.inf, np.ones(1, np.uint32))
    # Bad rays miss; a NaN sphere and a zero one are never hit.
    s2 = octoray.Scene()
    s2.add_instance(s2.add_spheres([[np.nan, 0, 0], [0, 0, 0]], [1.0, 0.0]))
    h = s2.closest(rays_at([[0, 0, 5], [np.nan, 0, 0]], [[0, 0, -1], [0, 0, 1]]))
    assert (h.prim == -1).all() and not np.isnan(h.t).any()


def test_scene_threads_give_the_same_bits():
    rng = np.random.default_rng(12)
    s = octoray.Scene()
    g = s.add_mesh(rng.uniform(-1, 1, (300, 3)), rng.integers(0, 300, (500, 3)))
    b = s.add_spheres(rng.uniform(-1, 1, (50, 3)), rng.uniform(0.05, 0.2, 50))
    for k in range(6):
        s.add_instance(g, translation(2 * k, 0, 0) @ rotation_scale(0.5 * k, k % 3, (1, 1, 1)))
        s.add_instance(b, translation(2 * k, 2, 0), mask=2)
    rays = rays_at(rng.uniform(-3, 13, (20000, 3)), rng.normal(size=(20000, 3)))
    a, c = s.closest(rays, threads=1), s.closest(rays, threads=4)
    for x, y in zip((a.t, a.prim, a.geom, a.inst, a.normal), (c.t, c.prim, c.geom, c.inst, c.normal)):
        assert x.tobytes() == y.tobytes()
    assert (a.geom == b).sum() > 100 and (a.geom == g).sum() > 100


def test_crossings_and_containment_through_instances():
    """A closed grid cube placed three times (the identity, moved, rotated a quarter turn and
    mirrored: maps exact in f32): containment equals the cube's own answer at each point as each
    map carries it into object space (inside any one, as they do not overlap; a point on a
    surface is moved along the object's axes), crossing counts the sum of the cube's counts
    along each carried ray, exactly."""
    from test_mesh import grid_cube

    v, f = grid_cube(3)
    quarter = np.array([[0, -1, 0, 10], [1, 0, 0, 0], [0, 0, -1, 0], [0, 0, 0, 1]], dtype=np.float64)
    places = [np.eye(4), translation(0, 8, 0), quarter]
    s = octoray.Scene("exact")
    g = s.add_mesh(v, f)
    for m in places:
        s.add_instance(g, m)
    cube = octoray.Mesh(v, f)
    to_object = [np.linalg.inv(m) for m in places]
    rng = np.random.default_rng(2)
    # Grid points (on faces, edges and vertices often) and grid-aligned rays.
    p = rng.integers(-2, 13, (3000, 3)) / rng.choice([1, 2], (3000, 1))
    carried = [(np.c_[p, np.ones(len(p))] @ w.T)[:, :3] for w in to_object]
    want = np.any([cube.contains(q) for q in carried], axis=0)
    np.testing.assert_array_equal(s.contains(p), want)
    d = rng.integers(-2, 3, (3000, 3)).astype(np.float64)
    keep = np.abs(d).sum(axis=1) > 0
    n = s.crossings(rays_at(p[keep], d[keep]), t_max=3.0)
    counts = [cube.crossings(rays_at(q[keep], d[keep] @ w[:3, :3].T), t_max=3.0) for q, w in zip(carried, to_object)]
    np.testing.assert_array_equal(n, np.sum(counts, axis=0))
    assert n.sum() > 500 and s.contains(p, mask=0).sum() == 0
    sd = s.signed_distance(p)
    np.testing.assert_array_equal(np.signbit(sd) & (sd != 0), want & (sd != 0))
    np.testing.assert_array_equal(np.abs(sd), s.closest_points(p).distance)
    with pytest.raises(ValueError, match="crossing rule"):
        st = octoray.Scene("standard")
        st.add_instance(st.add_mesh(v, f))
        st.contains(p)


def test_boxes_through_instances_against_placed_meshes():
    """The box query on a scene of moved, rotated and scaled mesh instances and a stretched ball
    against each placed mesh's own box query (triangles: the same faces away from touching) and
    the ellipsoid's."""
    rng = np.random.default_rng(6)
    v = rng.uniform(-1, 1, (80, 3)).astype(np.float32)
    f = rng.integers(0, 80, (120, 3))
    places = [translation(4, 0, 0), translation(-4, 0, 0) @ rotation_scale(0.6, 2, (1.5, 1, 0.5))]
    s = octoray.Scene()
    g = s.add_mesh(v, f)
    for m in places:
        s.add_instance(g, m, mask=1)
    b = s.add_spheres(np.zeros((1, 3)), np.ones(1))
    s.add_instance(b, translation(0, 6, 0) @ rotation_scale(0.0, 0, (3, 1, 1)), mask=2)
    for _ in range(40):
        c = rng.uniform(-6, 6, 3)
        h = rng.uniform(0.05, 2, 3)
        lo, hi = c - h, c + h
        got = s.overlapping(lo, hi)
        assert got.dtype == np.int64 and got.shape[1] == 3
        assert (np.diff(got[:, 0] * 10**6 + got[:, 2]) > 0).all()
        for k, m in enumerate(places):
            w = (np.c_[v, np.ones(len(v))] @ m.T)[:, :3].astype(np.float32)
            want = octoray.Mesh(w, f).overlapping(lo, hi)
            mine = got[got[:, 0] == k][:, 2]
            # Placed in f32 against carried in f64: the same faces but where one touches the box.
            assert len(np.setxor1d(mine, want)) <= 1
        ball = got[got[:, 1] == b]
        # The ellipsoid x^2/9 + (y - 6)^2 + z^2 <= 1 against the box: its nearest point, by a fine
        # sampling of the box, inside or not.
        t = np.linspace(0, 1, 24)
        grid = lo + np.stack(np.meshgrid(t, t, t), -1).reshape(-1, 3) * (hi - lo)
        inside = ((grid[:, 0] / 3) ** 2 + (grid[:, 1] - 6) ** 2 + grid[:, 2] ** 2).min()
        if inside < 0.97:
            assert len(ball) == 1
        if inside > 1.5:
            assert len(ball) == 0
    assert len(s.overlapping([-100] * 3, [100] * 3, mask=2)) == 1
    assert len(s.overlapping([1, 1, 1], [0, 0, 0])) == 0
    with pytest.raises(ValueError):
        s.overlapping([0, 0], [1, 1, 1])
