"""The trimesh adapter against trimesh's own ray interface (pure numpy, with rtree) on its
meshes, away from the edges where trimesh's answers depend on rounding."""

import numpy as np
import pytest

trimesh = pytest.importorskip("trimesh")
pytest.importorskip("rtree")

import octoray  # noqa: E402
import octoray.trimesh  # noqa: E402
from trimesh.ray.ray_triangle import RayMeshIntersector as Reference  # noqa: E402

MESHES = {
    "icosphere": lambda: trimesh.creation.icosphere(subdivisions=3),
    "box": lambda: trimesh.creation.box(extents=(1, 2, 3)),
    "torus": lambda: trimesh.creation.torus(major_radius=1.0, minor_radius=0.3),
    "capsule": lambda: trimesh.creation.capsule(height=1.0, radius=0.4),
}


def random_rays(mesh, n, seed):
    rng = np.random.default_rng(seed)
    lo, hi = mesh.bounds
    span = hi - lo
    o = rng.uniform(lo - span, hi + span, (n, 3))
    # Aim at points inside the box so that most rays hit.
    d = rng.uniform(lo, hi, (n, 3)) - o
    return o, d


@pytest.mark.parametrize("name", sorted(MESHES))
def test_first_and_any_match_trimesh(name):
    mesh = MESHES[name]()
    ours, ref = octoray.trimesh.RayMeshIntersector(mesh), Reference(mesh)
    o, d = random_rays(mesh, 3000, 5)
    first, expected = ours.intersects_first(o, d), ref.intersects_first(o, d)
    agree = (first == expected).mean()
    # Rays near an edge may name either neighbour in trimesh; nowhere else may they differ.
    assert agree > 0.995, agree
    np.testing.assert_array_equal(ours.intersects_any(o, d), first >= 0)
    assert (ours.intersects_any(o, d) == ref.intersects_any(o, d)).mean() > 0.995


@pytest.mark.parametrize("name", sorted(MESHES))
def test_locations_and_ids_match_trimesh(name):
    mesh = MESHES[name]()
    ours, ref = octoray.trimesh.RayMeshIntersector(mesh), Reference(mesh)
    o, d = random_rays(mesh, 500, 9)
    loc, ray, tri = ours.intersects_location(o, d)
    assert len(loc) == len(ray) == len(tri) > 100
    # Every location lies on its face's plane, along its ray.
    n = mesh.face_normals[tri]
    off = np.einsum("ij,ij->i", loc - mesh.triangles[tri][:, 0], n)
    assert np.abs(off).max() < 1e-5
    rloc, rray, rtri = ref.intersects_location(o, d, multiple_hits=True)
    # trimesh may report a hit on a shared edge twice; the sets agree elsewhere.
    ours_pairs, ref_pairs = set(zip(ray, tri)), set(zip(rray, rtri))
    assert len(ours_pairs ^ ref_pairs) <= 0.01 * len(ref_pairs) + 2
    # First hits only, and a cap on hits per ray.
    tri1, ray1 = ours.intersects_id(o, d, multiple_hits=False)
    assert len(set(ray1)) == len(ray1)
    tri2, ray2 = ours.intersects_id(o, d, max_hits=1)
    np.testing.assert_array_equal(np.sort(ray2), np.sort(ray1))


@pytest.mark.parametrize("name", sorted(MESHES))
def test_contains_matches_trimesh_away_from_the_surface(name):
    mesh = MESHES[name]()
    ours = octoray.trimesh.RayMeshIntersector(mesh)
    lo, hi = mesh.bounds
    pts = np.random.default_rng(2).uniform(lo - 0.2, hi + 0.2, (4000, 3))
    # Points farther than 1e-3 from the surface (octoray's distance; trimesh's needs scipy).
    far = np.abs(octoray.Mesh(mesh.vertices, mesh.faces).signed_distance(pts)) > 1e-3
    inside = ours.contains_points(pts)
    np.testing.assert_array_equal(inside[far], mesh.contains(pts)[far])


def test_mesh_ray_can_be_replaced():
    mesh = trimesh.creation.icosphere()
    mesh.ray = octoray.trimesh.RayMeshIntersector(mesh)
    hits = mesh.ray.intersects_first([[0, 0, -3]], [[0, 0, 1]])
    assert hits[0] >= 0
