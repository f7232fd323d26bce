"""trimesh's ray interface on octoray: :class:`RayMeshIntersector` answers the calls of
``trimesh.ray.ray_triangle.RayMeshIntersector`` (and of its Embree variant) with octoray's
watertight kernel, and ``contains_points`` exactly.

    import trimesh, octoray.trimesh
    mesh = trimesh.creation.icosphere()
    mesh.ray = octoray.trimesh.RayMeshIntersector(mesh)
    mesh.ray.intersects_first(origins, directions)

Only the mesh's ``vertices`` and ``faces`` are read, once: build a new intersector after
changing them. Hits lie at ``t >= 0`` along the (unnormalised) directions, as trimesh's.
"""

import numpy as np

from . import Mesh

__all__ = ["RayMeshIntersector"]


class RayMeshIntersector:
    """trimesh's ``RayMeshIntersector`` interface over an octoray :class:`~octoray.Mesh`."""

    def __init__(self, mesh, tier="watertight", threads=None):
        self.mesh = mesh
        self.threads = threads
        self._mesh = Mesh(np.asarray(mesh.vertices), np.asarray(mesh.faces), tier)

    def _rays(self, ray_origins, ray_directions):
        o = np.asarray(ray_origins, dtype=np.float64)
        d = np.asarray(ray_directions, dtype=np.float64)
        if o.ndim != 2 or o.shape[1] != 3 or d.shape != o.shape:
            raise ValueError(
                f"ray_origins and ray_directions must both have shape (n, 3), got {o.shape} and {d.shape}"
            )
        return o, d, np.hstack([o, d])

    def intersects_first(self, ray_origins, ray_directions, **kwargs):
        """The index of the first face each ray hits, ``-1`` for a miss."""
        _, _, rays = self._rays(ray_origins, ray_directions)
        return self._mesh.closest(rays, threads=self.threads).prim

    def intersects_any(self, ray_origins, ray_directions, **kwargs):
        """Whether each ray hits any face."""
        _, _, rays = self._rays(ray_origins, ray_directions)
        return self._mesh.occluded(rays, threads=self.threads)

    def intersects_id(
        self,
        ray_origins,
        ray_directions,
        multiple_hits=True,
        max_hits=None,
        return_locations=False,
        **kwargs,
    ):
        """``(index_tri, index_ray)`` of the hits (every hit, or the first per ray when
        ``multiple_hits`` is false; at most ``max_hits`` per ray), with their locations when
        ``return_locations``."""
        o, d, rays = self._rays(ray_origins, ray_directions)
        if multiple_hits:
            h = self._mesh.all_hits(rays, threads=self.threads)
            keep = np.ones(len(h.ray), dtype=bool)
            if max_hits is not None and np.isfinite(max_hits) and len(h.ray):
                # Rank of each hit within its ray (hits come ordered by ray, then t).
                start = np.r_[0, np.flatnonzero(np.diff(h.ray)) + 1]
                rank = np.arange(len(h.ray)) - np.repeat(start, np.diff(np.r_[start, len(h.ray)]))
                keep = rank < int(max_hits)
            index_ray, index_tri, t = h.ray[keep], h.prim[keep], h.t[keep]
        else:
            f = self._mesh.closest(rays, threads=self.threads)
            index_ray = np.flatnonzero(f.hit)
            index_tri, t = f.prim[index_ray], f.t[index_ray]
        if return_locations:
            locations = o[index_ray] + d[index_ray] * t[:, None].astype(np.float64)
            return index_tri, index_ray, locations
        return index_tri, index_ray

    def intersects_location(self, ray_origins, ray_directions, multiple_hits=True, **kwargs):
        """``(locations, index_ray, index_tri)`` of the hits, as :meth:`intersects_id`."""
        index_tri, index_ray, locations = self.intersects_id(
            ray_origins, ray_directions, multiple_hits=multiple_hits, return_locations=True
        )
        return locations, index_ray, index_tri

    def contains_points(self, points):
        """Whether each point is inside the mesh, exactly (it must be closed: every edge
        shared by two faces of opposite orientation; ``ValueError`` otherwise)."""
        return self._mesh.contains(np.asarray(points, dtype=np.float64), threads=self.threads)
