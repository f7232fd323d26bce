"""Ray casting over numpy arrays with octoray's watertight and exact kernels.

A :class:`Mesh` is built once from ``vertices`` (n, 3) and ``faces`` (m, 3); its queries take
batches of rays (rows ``ox, oy, oz, dx, dy, dz``) or points (rows ``x, y, z``), release the GIL
and use every core (``threads=1`` for one). Answers are the same bits on every machine and for
every number of threads.

Tiers (``tier=``): ``"watertight"`` (default; no ray escapes a closed mesh), ``"exact"`` (every
hit or miss exact for the float32 inputs), ``"standard"`` (Möller–Trumbore; rays may slip
through shared edges).

Bad input raises: ``ValueError`` for shapes, out-of-range face indices, unknown tiers and
queries that need a closed mesh on one that is not; ``TypeError`` for faces that are not
integers. Rays a kernel cannot trace (NaN, infinite, zero direction, empty range) miss.
"""

from dataclasses import dataclass

import numpy as np

from ._octoray import Mesh as _Mesh
from ._octoray import Scene as _Scene
from ._octoray import __version__

__all__ = [
    "Mesh",
    "Scene",
    "Hits",
    "SceneHits",
    "AllHits",
    "SceneAllHits",
    "ClosestPoints",
    "NearestFaces",
    "SceneClosestPoints",
    "TIERS",
    "__version__",
]

#: The tier names a mesh accepts.
TIERS = ("watertight", "exact", "standard")


@dataclass(frozen=True)
class Hits:
    """First hits, one entry per ray."""

    #: Ray parameter of the hit (float32); ``inf`` for a miss.
    t: np.ndarray
    #: Index of the face hit (int64); ``-1`` for a miss.
    prim: np.ndarray
    #: Barycentric weight of the face's second vertex (float32).
    u: np.ndarray
    #: Barycentric weight of the face's third vertex (float32).
    v: np.ndarray
    #: Unit geometric normal ``(v1 - v0) x (v2 - v0)`` of the face hit (n, 3); 0 for a miss.
    normal: np.ndarray
    #: Whether the ray met the face's front (the side its normal points to).
    front: np.ndarray

    @property
    def hit(self) -> np.ndarray:
        """Whether each ray hit anything."""
        return self.prim >= 0


@dataclass(frozen=True)
class SceneHits:
    """First hits through a scene, one entry per ray."""

    #: Ray parameter of the hit (float32); ``inf`` for a miss.
    t: np.ndarray
    #: Index of the primitive in its geometry (int64); ``-1`` for a miss.
    prim: np.ndarray
    #: Index of the geometry (int64); ``-1`` for a miss.
    geom: np.ndarray
    #: Index of the instance (int64); ``-1`` for a miss.
    inst: np.ndarray
    #: Barycentric weights on a triangle (float32; 0 on a sphere).
    u: np.ndarray
    v: np.ndarray
    #: Unit geometric normal in world space (n, 3): a triangle's ``(v1 - v0) x (v2 - v0)`` of its
    #: placed vertices, a sphere's outward normal; 0 for a miss.
    normal: np.ndarray
    #: Whether the ray met the front (the side the normal points to).
    front: np.ndarray

    @property
    def hit(self) -> np.ndarray:
        """Whether each ray hit anything."""
        return self.prim >= 0


@dataclass(frozen=True)
class AllHits:
    """Every hit of every ray, flat, ordered by ray then ``t``; each face once per ray."""

    #: Index of the ray (int64).
    ray: np.ndarray
    #: Index of the face (int64).
    prim: np.ndarray
    #: Ray parameter (float32).
    t: np.ndarray
    #: Barycentric weights (float32).
    u: np.ndarray
    v: np.ndarray


@dataclass(frozen=True)
class ClosestPoints:
    """The nearest point of the mesh to each query point."""

    #: The nearest point (n, 3) float32; NaN where none lies within the bound.
    point: np.ndarray
    #: Its distance (float32); ``inf`` where none lies within the bound.
    distance: np.ndarray
    #: Index of its face (int64); ``-1`` where none lies within the bound.
    prim: np.ndarray
    #: Its barycentric weights on the face (float32).
    u: np.ndarray
    v: np.ndarray


@dataclass(frozen=True)
class NearestFaces:
    """The ``k`` faces of the mesh nearest to each query point, nearest first."""

    #: Their distances (n, k) float32; ``inf`` past the faces found.
    distance: np.ndarray
    #: Their faces (n, k) int64; ``-1`` past the faces found.
    prim: np.ndarray
    #: Whether the row holds every face within the radius (bool); false when ``k`` faces were
    #: found and more may lie within it (none nearer than the last).
    complete: np.ndarray


@dataclass(frozen=True)
class SceneAllHits:
    """Every hit of every ray through a scene, flat, ordered by ray then ``t`` (then instance,
    geometry, primitive); each primitive once per ray."""

    #: Index of the ray (int64).
    ray: np.ndarray
    #: Index of the primitive in its geometry, of the geometry and of the instance (int64).
    prim: np.ndarray
    geom: np.ndarray
    inst: np.ndarray
    #: Ray parameter (float32).
    t: np.ndarray
    #: Barycentric weights on a triangle (float32; 0 on a sphere).
    u: np.ndarray
    v: np.ndarray


@dataclass(frozen=True)
class SceneClosestPoints:
    """The nearest point of a scene to each query point."""

    #: The nearest point (n, 3) float32; NaN where none lies within the bound.
    point: np.ndarray
    #: Its distance (float32); ``inf`` where none lies within the bound.
    distance: np.ndarray
    #: Its primitive, geometry and instance (int64); ``-1`` where none lies within the bound.
    prim: np.ndarray
    geom: np.ndarray
    inst: np.ndarray
    #: Its barycentric weights on a triangle (float32; 0 on a sphere).
    u: np.ndarray
    v: np.ndarray


def _rows(a, width, name, dtype=np.float32):
    """``a`` as a C-contiguous (n, width) array of ``dtype``, or ``ValueError``."""
    a = np.asarray(a)
    if a.ndim != 2 or a.shape[1] != width:
        raise ValueError(f"{name} must have shape (n, {width}), got {a.shape}")
    return np.ascontiguousarray(a, dtype=dtype)


def _range(value, n, name):
    """A scalar or (n,) bound as a contiguous float32 (n,) array, or ``ValueError``."""
    a = np.asarray(value, dtype=np.float32)
    if a.ndim > 1 or (a.ndim == 1 and a.shape[0] != n):
        raise ValueError(f"{name} must be a scalar or have shape ({n},), got {a.shape}")
    return np.ascontiguousarray(np.broadcast_to(a, (n,)))


def _threads(threads):
    if threads is None:
        return None
    if isinstance(threads, bool) or not isinstance(threads, (int, np.integer)) or threads < 1:
        raise ValueError(f"threads must be None or an integer >= 1, got {threads!r}")
    return int(threads)


class Mesh:
    """A triangle mesh and its BVH, built once; every query is batched.

    ``vertices``: (n, 3) numbers (rounded to float32); ``faces``: (m, 3) integer indices into
    them. ``tier``: one of :data:`TIERS`.
    """

    def __init__(self, vertices, faces, tier="watertight"):
        vertices = _rows(vertices, 3, "vertices")
        faces = np.asarray(faces)
        if faces.size and not np.issubdtype(faces.dtype, np.integer):
            raise TypeError(f"faces must be integers, got {faces.dtype}")
        faces = _rows(faces, 3, "faces", dtype=np.int64)
        if not isinstance(tier, str):
            raise TypeError(f"tier must be a string, got {type(tier).__name__}")
        self._mesh = _Mesh(vertices, faces, tier)

    @property
    def triangle_count(self) -> int:
        """The number of faces."""
        return self._mesh.triangle_count

    @property
    def tier(self) -> str:
        """The tier rays are answered with."""
        return self._mesh.tier

    @property
    def is_closed(self) -> bool:
        """Every edge shared by exactly two faces with opposite orientation (what
        :meth:`contains`, :meth:`winding_number` and :meth:`signed_distance` need)."""
        return self._mesh.is_closed

    def _rays(self, rays, t_min, t_max):
        rays = _rows(rays, 6, "rays")
        n = rays.shape[0]
        return rays, _range(t_min, n, "t_min"), _range(t_max, n, "t_max")

    def closest(self, rays, t_min=0.0, t_max=np.inf, threads=None) -> Hits:
        """The first hit of each ray (rows ``ox, oy, oz, dx, dy, dz``) with ``t`` in
        ``[t_min, t_max]`` (scalars or one per ray)."""
        r, lo, hi = self._rays(rays, t_min, t_max)
        return Hits(*self._mesh.closest(r, lo, hi, _threads(threads)))

    def occluded(self, rays, t_min=0.0, t_max=np.inf, threads=None) -> np.ndarray:
        """Whether each ray hits anything with ``t`` in ``[t_min, t_max]`` (bool array)."""
        r, lo, hi = self._rays(rays, t_min, t_max)
        return self._mesh.occluded(r, lo, hi, _threads(threads))

    def all_hits(self, rays, t_min=0.0, t_max=np.inf, threads=None) -> AllHits:
        """Every hit of each ray with ``t`` in ``[t_min, t_max]``, each face once per ray."""
        r, lo, hi = self._rays(rays, t_min, t_max)
        return AllHits(*self._mesh.all_hits(r, lo, hi, _threads(threads)))

    def crossings(self, rays, t_min=0.0, t_max=np.inf, threads=None) -> np.ndarray:
        """How many faces each ray crosses in ``(t_min, t_max)``, exactly: a ray through a
        shared edge or vertex crosses one face there, once (uint32 array). For a closed mesh the
        parity says whether the ray's ends are on the same side."""
        r, lo, hi = self._rays(rays, t_min, t_max)
        return self._mesh.crossings(r, lo, hi, _threads(threads))

    def contains(self, points, threads=None) -> np.ndarray:
        """Whether each point is inside the closed mesh, exactly (bool array). A point on the
        surface counts as moved an infinitesimal step along +x, then +y, then +z. Raises
        ``ValueError`` if the mesh is not closed."""
        return self._mesh.contains(_rows(points, 3, "points"), _threads(threads))

    def winding_number(self, points, threads=None) -> np.ndarray:
        """The winding number of the closed mesh around each point (int32 array; 1 inside an
        outward-oriented mesh, 0 outside). Raises ``ValueError`` if the mesh is not closed."""
        return self._mesh.winding_number(_rows(points, 3, "points"), _threads(threads))

    def generalized_winding_number(self, points, tolerance=1e-3, threads=None) -> np.ndarray:
        """The generalized winding number at each point (float64 array), for any mesh: open,
        non-manifold or self-intersecting (1 inside and 0 outside a closed, outward-oriented
        mesh, 0.5 on its surface; a threshold at 0.5 classifies inside and outside). Within
        ``tolerance`` of the exact sum of the faces' solid angles over 4π (a proven bound; 0
        sums every face). NaN for a non-finite point. Raises ``ValueError`` for a negative or
        NaN tolerance."""
        p = _rows(points, 3, "points")
        return self._mesh.generalized_winding_number(p, float(tolerance), _threads(threads))

    def signed_distance(self, points, threads=None) -> np.ndarray:
        """The distance from each point to the closed mesh, negative inside (float32 array; the
        sign exact; NaN for a non-finite point). Raises ``ValueError`` if the mesh is not
        closed."""
        return self._mesh.signed_distance(_rows(points, 3, "points"), _threads(threads))

    def overlapping(self, lo, hi) -> np.ndarray:
        """The faces that meet the closed box ``[lo, hi]`` (int64 indices, ascending; exact but
        for faces touching the box within a few units of 2**-50 of its coordinates). A box with
        a NaN corner or ``lo > hi`` on an axis meets nothing."""
        return self._mesh.overlapping(_corner(lo, "lo"), _corner(hi, "hi"))

    def closest_points(self, points, max_distance=np.inf, threads=None) -> ClosestPoints:
        """The nearest point of the mesh to each point, within ``max_distance``."""
        p = _rows(points, 3, "points")
        d = float(max_distance)
        return ClosestPoints(*self._mesh.closest_points(p, d, _threads(threads)))

    def nearest_within(self, points, k, radius=np.inf, threads=None) -> NearestFaces:
        """The ``k`` faces nearest to each point within ``radius`` (inclusive), nearest first
        (equal distances by face index), each face once; ``radius=inf`` gives the k nearest.
        Raises ``ValueError`` for a ``k`` above the face count or a NaN or negative radius."""
        p = _rows(points, 3, "points")
        return NearestFaces(*self._mesh.nearest_within(p, int(k), float(radius), _threads(threads)))


def _corner(x, name):
    """A box corner as three floats."""
    c = np.asarray(x, dtype=np.float32)
    if c.shape != (3,):
        raise ValueError(f"{name} must be 3 numbers, got shape {c.shape}")
    return c.tolist()


def _placement(transform):
    """An object-to-world matrix, (4, 4) or (3, 4), as its 12 top entries by rows."""
    if transform is None:
        return [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0]
    m = np.asarray(transform, dtype=np.float64)
    if m.shape == (4, 4):
        if not np.array_equal(m[3], [0, 0, 0, 1]):
            raise ValueError("a (4, 4) transform must be affine: last row (0, 0, 0, 1)")
        m = m[:3]
    if m.shape != (3, 4):
        raise ValueError(f"transform must have shape (4, 4) or (3, 4), got {m.shape}")
    return m.ravel().tolist()


def _mask(mask, n):
    """A scalar mask or one per ray as a contiguous uint32 (n,) array."""
    a = np.asarray(mask)
    if a.size and not np.issubdtype(a.dtype, np.integer):
        raise TypeError(f"mask must be integers, got {a.dtype}")
    if (a < 0).any() or (a > 0xFFFFFFFF).any():
        raise ValueError("mask must lie in [0, 2**32)")
    if a.ndim > 1 or (a.ndim == 1 and a.shape[0] != n):
        raise ValueError(f"mask must be a scalar or have shape ({n},), got {a.shape}")
    return np.ascontiguousarray(np.broadcast_to(a.astype(np.uint32), (n,)))


class Scene:
    """Triangle meshes and sphere sets (geometries) placed in the world by instances.

    Add geometries, place them with :meth:`add_instance`, then query; the scene commits itself
    (builds its top level) before the first query after a change. ``tier``: one of
    :data:`TIERS` (spheres are always traced with the cancellation-free test).
    """

    def __init__(self, tier="watertight"):
        if not isinstance(tier, str):
            raise TypeError(f"tier must be a string, got {type(tier).__name__}")
        self._scene = _Scene(tier)
        self._changed = True

    @property
    def tier(self) -> str:
        """The tier triangles are answered with."""
        return self._scene.tier

    def add_mesh(self, vertices, faces) -> int:
        """Adds a triangle mesh; returns its geometry index."""
        vertices = _rows(vertices, 3, "vertices")
        faces = np.asarray(faces)
        if faces.size and not np.issubdtype(faces.dtype, np.integer):
            raise TypeError(f"faces must be integers, got {faces.dtype}")
        self._changed = True
        return self._scene.add_mesh(vertices, _rows(faces, 3, "faces", dtype=np.int64))

    def add_spheres(self, centers, radii) -> int:
        """Adds spheres, ``centers`` (n, 3) and ``radii`` (n,) or one radius; returns their
        geometry index."""
        centers = _rows(centers, 3, "centers")
        self._changed = True
        return self._scene.add_spheres(centers, _range(radii, centers.shape[0], "radii"))

    def add_instance(self, geometries, transform=None, mask=0xFFFFFFFF) -> int:
        """Places geometries (an index or a list of them, all meshes or all sphere sets, one
        tree over them) by the object-to-world matrix ``transform`` ((4, 4) or (3, 4); the
        identity when None), visible to rays whose mask shares a bit with ``mask``; returns the
        instance index. Raises ``ValueError`` for a matrix that is not finite or not
        invertible."""
        g = np.atleast_1d(np.asarray(geometries))
        if g.size and not np.issubdtype(g.dtype, np.integer):
            raise TypeError(f"geometries must be integers, got {g.dtype}")
        if g.ndim != 1 or (g < 0).any() or (g > 0xFFFFFFFF).any():
            raise ValueError("geometries must be geometry indices")
        mask = int(_mask(mask, 1)[0])
        self._changed = True
        return self._scene.add_instance(g.tolist(), _placement(transform), mask)

    def commit(self):
        """Builds the top level over the instances (done by the next query otherwise)."""
        self._scene.commit()
        self._changed = False

    def _query(self, rays, t_min, t_max, mask):
        if self._changed:
            self.commit()
        rays = _rows(rays, 6, "rays")
        n = rays.shape[0]
        return rays, _range(t_min, n, "t_min"), _range(t_max, n, "t_max"), _mask(mask, n)

    def closest(self, rays, t_min=0.0, t_max=np.inf, mask=0xFFFFFFFF, threads=None) -> SceneHits:
        """The first hit of each ray (rows ``ox, oy, oz, dx, dy, dz``) with ``t`` in
        ``[t_min, t_max]``, among the instances whose mask shares a bit with the ray's (scalars
        or one per ray)."""
        q = self._query(rays, t_min, t_max, mask)
        return SceneHits(*self._scene.closest(*q, _threads(threads)))

    def occluded(self, rays, t_min=0.0, t_max=np.inf, mask=0xFFFFFFFF, threads=None) -> np.ndarray:
        """Whether each ray hits anything, as :meth:`closest` sees the scene (bool array)."""
        q = self._query(rays, t_min, t_max, mask)
        return self._scene.occluded(*q, _threads(threads))

    def all_hits(self, rays, t_min=0.0, t_max=np.inf, mask=0xFFFFFFFF, threads=None) -> SceneAllHits:
        """Every hit of each ray with ``t`` in ``[t_min, t_max]``, as :meth:`closest` sees the
        scene; each primitive once per ray."""
        q = self._query(rays, t_min, t_max, mask)
        return SceneAllHits(*self._scene.all_hits(*q, _threads(threads)))

    def crossings(self, rays, t_min=0.0, t_max=np.inf, mask=0xFFFFFFFF, threads=None) -> np.ndarray:
        """How many faces of the instanced meshes each ray crosses in ``(t_min, t_max)``,
        exactly: a ray through a shared edge or vertex crosses one face there, once, in each
        instance's object space; spheres do not count (uint32 array). Raises ``ValueError`` for
        a ``"standard"`` scene."""
        q = self._query(rays, t_min, t_max, mask)
        return self._scene.crossings(*q, _threads(threads))

    def contains(self, points, mask=0xFFFFFFFF, threads=None) -> np.ndarray:
        """Whether each point is inside the instanced closed meshes whose mask shares a bit with
        ``mask`` (inside an odd number of them; bool array), exactly for the point as each
        instance's map carries it. Meaningful when every mesh is closed; spheres do not count.
        Raises ``ValueError`` for a ``"standard"`` scene."""
        if self._changed:
            self.commit()
        p = _rows(points, 3, "points")
        m = int(_mask(mask, 1)[0])
        return self._scene.contains(p, m, _threads(threads))

    def signed_distance(self, points, mask=0xFFFFFFFF, threads=None) -> np.ndarray:
        """The distance from each point to the nearest primitive of the instances whose mask
        shares a bit with ``mask``, negative inside the closed meshes (float32 array; the sign
        exact, as :meth:`contains`; NaN for a non-finite point). Raises ``ValueError`` for a
        ``"standard"`` scene."""
        if self._changed:
            self.commit()
        p = _rows(points, 3, "points")
        m = int(_mask(mask, 1)[0])
        return self._scene.signed_distance(p, m, _threads(threads))

    def overlapping(self, lo, hi, mask=0xFFFFFFFF) -> np.ndarray:
        """The primitives of the instances whose mask shares a bit with ``mask`` that meet the
        closed world box ``[lo, hi]``: (n, 3) int64 rows of instance, geometry and primitive,
        ascending, each once. Each is tested in world space (an instanced sphere as the
        ellipsoid its instance makes of it)."""
        if self._changed:
            self.commit()
        m = int(_mask(mask, 1)[0])
        return self._scene.overlapping(_corner(lo, "lo"), _corner(hi, "hi"), m)

    def closest_points(self, points, max_distance=np.inf, mask=0xFFFFFFFF, threads=None) -> SceneClosestPoints:
        """The nearest point of the scene (its instances whose mask shares a bit with
        ``mask``) to each point, within ``max_distance``."""
        if self._changed:
            self.commit()
        p = _rows(points, 3, "points")
        m = int(_mask(mask, 1)[0])
        return SceneClosestPoints(*self._scene.closest_points(p, float(max_distance), m, _threads(threads)))
