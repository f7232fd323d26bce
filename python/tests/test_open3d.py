"""The Open3D-style adapter: its answers are the Mesh's, under Open3D's names and conventions;
and Open3D's own where it is installed."""

import numpy as np
import pytest

import octoray
from octoray.open3d import INVALID_ID, RaycastingScene
from test_mesh import grid_cube


def two_cubes():
    v, f = grid_cube(3)
    return (v, f), (v + np.float32(5), f)


def test_adapter_answers_are_the_meshes():
    (v1, f1), (v2, f2) = two_cubes()
    scene = RaycastingScene()
    assert scene.add_triangles(v1, f1) == 0 and scene.add_triangles(v2, f2) == 1
    rng = np.random.default_rng(6)
    rays = np.hstack([rng.uniform(-2, 10, (2000, 3)), rng.normal(size=(2000, 3))]).astype(np.float32)
    ans = scene.cast_rays(rays)
    a, b = octoray.Mesh(v1, f1).closest(rays), octoray.Mesh(v2, f2).closest(rays)
    first = np.where(a.t <= b.t, a.t, b.t)
    np.testing.assert_array_equal(ans["t_hit"], first)
    miss = ~np.isfinite(first)
    assert (ans["geometry_ids"][miss] == INVALID_ID).all()
    assert (ans["geometry_ids"][~miss] == np.where(a.t <= b.t, 0, 1)[~miss]).all()
    assert ans["primitive_uvs"].shape == (2000, 2) and ans["primitive_normals"].shape == (2000, 3)
    np.testing.assert_array_equal(scene.test_occlusions(rays), ~miss)
    counts = scene.count_intersections(rays)
    m1, m2 = octoray.Mesh(v1, f1), octoray.Mesh(v2, f2)
    np.testing.assert_array_equal(counts, m1.crossings(rays) + m2.crossings(rays))
    pts = rng.uniform(-2, 10, (3000, 3)).astype(np.float32)
    occ = scene.compute_occupancy(pts)
    np.testing.assert_array_equal(occ > 0, m1.contains(pts) | m2.contains(pts))
    d = scene.compute_distance(pts)
    np.testing.assert_array_equal(d, np.minimum(m1.signed_distance(pts).__abs__(), m2.signed_distance(pts).__abs__()))
    sd = scene.compute_signed_distance(pts)
    np.testing.assert_array_equal(sd < 0, occ > 0)
    c = scene.compute_closest_points(pts)
    np.testing.assert_allclose(np.linalg.norm(c["points"] - pts, axis=1), d, rtol=1e-5, atol=1e-6)
    assert set(np.unique(c["geometry_ids"])) == {0, 1}


def test_same_as_open3d_where_installed():
    o3d = pytest.importorskip("open3d")
    (v, f), _ = two_cubes()
    ours = RaycastingScene()
    ours.add_triangles(v, f)
    theirs = o3d.t.geometry.RaycastingScene()
    theirs.add_triangles(o3d.core.Tensor(v), o3d.core.Tensor(f.astype(np.uint32)))
    rng = np.random.default_rng(2)
    rays = np.hstack([rng.uniform(-2, 5, (2000, 3)), rng.normal(size=(2000, 3))]).astype(np.float32)
    a, b = ours.cast_rays(rays), theirs.cast_rays(o3d.core.Tensor(rays))
    same = a["primitive_ids"] == b["primitive_ids"].numpy()
    assert same.mean() > 0.99
    np.testing.assert_allclose(a["t_hit"][same], b["t_hit"].numpy()[same], rtol=1e-5)
