"""Open3D's ``RaycastingScene`` calls on octoray, one to one, over numpy arrays (Open3D takes and
returns ``o3d.core.Tensor``; here arrays in, dicts of arrays out, under the same keys).

    scene = octoray.open3d.RaycastingScene()
    scene.add_triangles(vertices, triangles)
    ans = scene.cast_rays(rays)          # ans["t_hit"], ans["primitive_ids"], ...

Differences: ``count_intersections`` counts crossings exactly (a ray through a shared edge or
vertex crosses one face there, once); ``compute_occupancy`` and the sign of
``compute_signed_distance`` come from that exact parity, so they are never wrong for closed
meshes; the invalid ID is ``INVALID_ID`` (2**32 - 1), as Open3D's.
"""

import numpy as np

from . import Mesh, Scene

__all__ = ["RaycastingScene", "INVALID_ID"]

#: The ID of no geometry or primitive.
INVALID_ID = 0xFFFFFFFF


def _ids(a):
    return np.where(a < 0, INVALID_ID, a).astype(np.uint32)


class RaycastingScene:
    """Triangle meshes, each placed as it is; the queries of Open3D's ``RaycastingScene``."""

    def __init__(self, tier="watertight"):
        self._tier = tier
        self._scene = Scene(tier)
        self._meshes = []

    def add_triangles(self, vertex_positions, triangle_indices):
        """Adds a mesh; returns its geometry ID."""
        v = np.asarray(vertex_positions, dtype=np.float32)
        f = np.asarray(triangle_indices)
        mesh = Mesh(v, f, self._tier)
        g = self._scene.add_mesh(v, f)
        self._scene.add_instance(g)
        self._meshes.append(mesh)
        return g

    def cast_rays(self, rays, nthreads=0):
        """The first hit of each ray (rows ``ox, oy, oz, dx, dy, dz``): ``t_hit`` (inf: miss),
        ``geometry_ids``, ``primitive_ids``, ``primitive_uvs``, ``primitive_normals``."""
        h = self._scene.closest(np.asarray(rays).reshape(-1, 6), threads=nthreads or None)
        return {
            "t_hit": h.t,
            "geometry_ids": _ids(h.geom),
            "primitive_ids": _ids(h.prim),
            "primitive_uvs": np.stack([h.u, h.v], axis=-1),
            "primitive_normals": h.normal,
        }

    def test_occlusions(self, rays, tnear=0.0, tfar=np.inf, nthreads=0):
        """Whether each ray hits anything with ``t`` in ``[tnear, tfar]``."""
        r = np.asarray(rays).reshape(-1, 6)
        return self._scene.occluded(r, t_min=tnear, t_max=tfar, threads=nthreads or None)

    def count_intersections(self, rays, nthreads=0):
        """How many faces each ray crosses, exactly, over every mesh (int32)."""
        r = np.asarray(rays).reshape(-1, 6)
        counts = np.zeros(len(r), dtype=np.int64)
        for m in self._meshes:
            counts += m.crossings(r, threads=nthreads or None)
        return counts.astype(np.int32)

    def compute_closest_points(self, query_points, nthreads=0):
        """The nearest surface point to each point: ``points``, ``geometry_ids``,
        ``primitive_ids``, ``primitive_uvs``."""
        p = np.asarray(query_points).reshape(-1, 3)
        best = None
        for g, m in enumerate(self._meshes):
            c = m.closest_points(p, threads=nthreads or None)
            if best is None:
                best = {"d": c.distance, "points": c.point, "g": np.where(c.prim >= 0, g, -1),
                        "p": c.prim, "u": c.u, "v": c.v}
                continue
            nearer = c.distance < best["d"]
            for key, value in (("d", c.distance), ("points", c.point), ("p", c.prim),
                               ("u", c.u), ("v", c.v)):
                best[key] = np.where(nearer[:, None] if value.ndim == 2 else nearer, value, best[key])
            best["g"] = np.where(nearer, g, best["g"])
        if best is None:
            n = len(p)
            best = {"d": np.full(n, np.inf, np.float32), "points": np.full((n, 3), np.nan, np.float32),
                    "g": np.full(n, -1), "p": np.full(n, -1), "u": np.zeros(n, np.float32),
                    "v": np.zeros(n, np.float32)}
        return {
            "points": best["points"],
            "geometry_ids": _ids(best["g"]),
            "primitive_ids": _ids(best["p"]),
            "primitive_uvs": np.stack([best["u"], best["v"]], axis=-1),
        }

    def compute_distance(self, query_points, nthreads=0):
        """The distance from each point to the nearest surface point."""
        p = np.asarray(query_points).reshape(-1, 3)
        d = np.full(len(p), np.inf, dtype=np.float32)
        for m in self._meshes:
            d = np.minimum(d, m.closest_points(p, threads=nthreads or None).distance)
        return d

    def compute_occupancy(self, query_points, nthreads=0):
        """1 where a point is inside (an odd number of exact crossings of a ray from it over
        every mesh), else 0 (float32, as Open3D's)."""
        p = np.asarray(query_points, dtype=np.float32).reshape(-1, 3)
        # The direction the library's own containment casts in: off the axes and diagonals.
        d = np.broadcast_to(np.array([1.0, 0.3713, 0.1947], dtype=np.float32), p.shape)
        return (self.count_intersections(np.hstack([p, d]), nthreads) % 2).astype(np.float32)

    def compute_signed_distance(self, query_points, nthreads=0):
        """The distance to the nearest surface point, negative inside (the sign from the exact
        occupancy)."""
        d = self.compute_distance(query_points, nthreads)
        return np.where(self.compute_occupancy(query_points, nthreads) > 0, -d, d)
