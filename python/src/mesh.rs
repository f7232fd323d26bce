//! `Mesh`: one triangle mesh, its 8-wide BVH built once, and the batched queries over it.

use crate::arrays::{self, map_into, Bools, F32s, I64s, Rows3};
use crate::tier::Tier;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use octoray::bvh::{Bvh8, Solid, WindingTree};
use octoray::f32x8;
use octoray::glam::Vec3;
use octoray::hit::Hit;
use octoray::kernels::{Exact, MollerTrumbore, Watertight};
use octoray::parallel::Rayon;
use octoray::prim::{PackedTriangle, Ray, VertexTriangle};
use octoray::tree;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// A triangle mesh and its BVH: first hits, occlusion and every hit along rays with the chosen
/// tier; exact crossing counts, containment, winding numbers and signed distance (closed
/// meshes); generalized winding numbers (any mesh); closest points.
#[pyclass(frozen, module = "octoray._octoray")]
pub struct Mesh {
    tier: Tier,
    /// The triangles, their tree and the closed-mesh check over them.
    mesh: Checked,
    /// Each triangle's unit geometric normal.
    normals: Vec<[f32; 3]>,
    /// The standard tier's layout of the same triangles.
    packed: Option<Bvh8<PackedTriangle>>,
}

/// The triangles and their tree.
struct Owned {
    tris: Vec<VertexTriangle>,
    bvh: Bvh8<VertexTriangle>,
}

/// The closed mesh over [`Owned`], or why it is not closed.
type Closed<'a> = Result<Solid<'a>, String>;

self_cell::self_cell!(
    /// [`Owned`] and its [`Closed`] view, checked once.
    struct Checked {
        owner: Owned,
        #[covariant]
        dependent: Closed,
    }
);

/// The first hits as arrays: `t` (inf: miss), primitive (−1: miss), `u`, `v`, the unit
/// geometric normal `(v1 − v0) × (v2 − v0)` (0: miss) and whether the ray met the front.
type FirstHits<'py> = (
    F32s<'py>,
    I64s<'py>,
    F32s<'py>,
    F32s<'py>,
    Rows3<'py>,
    Bools<'py>,
);

/// Every hit, flat, by ray then `t`: ray index, primitive, `t`, `u`, `v`.
type EveryHit<'py> = (I64s<'py>, I64s<'py>, F32s<'py>, F32s<'py>, F32s<'py>);

/// The closest points: the point, its distance (inf: none within the bound), primitive (−1:
/// none), `u`, `v`.
type NearestPoints<'py> = (Rows3<'py>, F32s<'py>, I64s<'py>, F32s<'py>, F32s<'py>);

/// The `k` nearest faces of each point: `(n, k)` distances (inf past those found) and faces
/// (−1 past them), and whether each row holds every face within the radius.
type NearestFaces<'py> = (
    Bound<'py, numpy::PyArray2<f32>>,
    Bound<'py, numpy::PyArray2<i64>>,
    Bools<'py>,
);

impl Mesh {
    /// The closed mesh as a [`Solid`], or the `ValueError` saying why it is not one.
    fn solid(&self) -> PyResult<Solid<'_>> {
        self.mesh
            .borrow_dependent()
            .clone()
            .map_err(|why| PyValueError::new_err(format!("the mesh is not closed: {why}")))
    }

    /// The triangles.
    fn tris(&self) -> &[VertexTriangle] {
        &self.mesh.borrow_owner().tris
    }

    /// Their tree.
    fn bvh(&self) -> octoray::bvh::Bvh8Ref<'_, VertexTriangle> {
        self.mesh.borrow_owner().bvh.as_ref()
    }

    /// The first hit of every ray with this mesh's tier.
    fn first_hits(&self, rays: &[Ray], pool: Option<&rayon::ThreadPool>) -> Vec<Option<Hit>> {
        let mut hits = vec![None; rays.len()];
        match (self.tier, &self.packed) {
            (Tier::Standard, Some(p)) => map_into(pool, rays, &mut hits, |_, r, o| {
                tree::closest::<f32x8, MollerTrumbore>(p.as_ref(), r, o)
            }),
            (Tier::Exact, _) => map_into(pool, rays, &mut hits, |_, r, o| {
                tree::closest::<f32x8, Exact>(self.bvh(), r, o)
            }),
            _ => map_into(pool, rays, &mut hits, |_, r, o| {
                tree::closest::<f32x8, Watertight>(self.bvh(), r, o)
            }),
        }
        hits
    }

    /// Every hit of every ray with this mesh's tier, by ray then hit order (the all-hits
    /// query's body).
    fn every_hits(&self, rays: &[Ray], pool: Option<&rayon::ThreadPool>) -> Vec<(usize, Hit)> {
        arrays::collect(pool, rays, |i, ray, out| match (self.tier, &self.packed) {
            (Tier::Standard, Some(p)) => arrays::paged(i, out, |after, page| {
                tree::all_hits_ray::<f32x8, MollerTrumbore>(p.as_ref(), ray, after, page)
            }),
            (Tier::Exact, _) => arrays::paged(i, out, |after, page| {
                tree::all_hits_ray::<f32x8, Exact>(self.bvh(), ray, after, page)
            }),
            _ => arrays::paged(i, out, |after, page| {
                tree::all_hits_ray::<f32x8, Watertight>(self.bvh(), ray, after, page)
            }),
        })
    }
}

#[pymethods]
impl Mesh {
    /// A mesh from `vertices` (n, 3) float32 and `faces` (m, 3) int64 indices into them, its
    /// rays answered with `tier`. Raises `ValueError` for a bad shape, an index out of range or
    /// an unknown tier.
    #[new]
    #[pyo3(signature = (vertices, faces, tier = "watertight"))]
    fn new(
        py: Python<'_>,
        vertices: PyReadonlyArray2<'_, f32>,
        faces: PyReadonlyArray2<'_, i64>,
        tier: &str,
    ) -> PyResult<Self> {
        let tier = Tier::parse(tier)?;
        let tris = arrays::triangles(&vertices, &faces)?;
        py.detach(move || -> Result<Self, String> {
            // On rayon's threads; the same tree as a single-threaded build's.
            let bvh = Bvh8::try_build_on(&tris, &Rayon).map_err(|e| e.to_string())?;
            let packed = if tier == Tier::Standard {
                let p = arrays::packed(&tris);
                Some(Bvh8::try_build_on(&p, &Rayon).map_err(|e| e.to_string())?)
            } else {
                None
            };
            let normals = arrays::unit_normals(&tris);
            let mesh = Checked::new(Owned { tris, bvh }, |o| {
                Solid::new(o.bvh.as_ref(), &o.tris).map_err(|e| e.to_string())
            });
            Ok(Self {
                tier,
                mesh,
                normals,
                packed,
            })
        })
        .map_err(PyValueError::new_err)
    }

    /// The number of triangles.
    #[getter]
    fn triangle_count(&self) -> usize {
        self.tris().len()
    }

    /// The tier's name.
    #[getter]
    fn tier(&self) -> &'static str {
        self.tier.name()
    }

    /// Whether every edge is shared by exactly two triangles with opposite orientation: what
    /// `contains`, `winding_number` and `signed_distance` need.
    #[getter]
    fn is_closed(&self) -> bool {
        self.mesh.borrow_dependent().is_ok()
    }

    /// The first hit of every ray (rows `ox, oy, oz, dx, dy, dz`, hits with `t` in
    /// `[t_min, t_max]`): `(t, prim, u, v, normal, front)` ([`FirstHits`]).
    #[pyo3(signature = (rays, t_min, t_max, threads = None))]
    fn closest<'py>(
        &self,
        py: Python<'py>,
        rays: PyReadonlyArray2<'py, f32>,
        t_min: PyReadonlyArray1<'py, f32>,
        t_max: PyReadonlyArray1<'py, f32>,
        threads: Option<usize>,
    ) -> PyResult<FirstHits<'py>> {
        let rays = arrays::rays(&rays, &t_min, &t_max)?;
        let pool = arrays::pool(threads)?;
        let hits = py.detach(|| self.first_hits(&rays, pool.as_ref()));
        let n = rays.len();
        let (mut t, mut prim) = (vec![f32::INFINITY; n], vec![-1i64; n]);
        let (mut u, mut v) = (vec![0f32; n], vec![0f32; n]);
        let (mut normal, mut front) = (vec![0f32; 3 * n], vec![false; n]);
        for (i, (h, ray)) in hits.iter().zip(&rays).enumerate() {
            let Some(h) = h else { continue };
            (t[i], prim[i], u[i], v[i]) = (h.t, i64::from(h.prim), h.u, h.v);
            let n = self.normals[h.prim as usize];
            normal[3 * i..3 * i + 3].copy_from_slice(&n);
            front[i] = arrays::meets_front(n, ray.dir);
        }
        Ok((
            PyArray1::from_vec(py, t),
            PyArray1::from_vec(py, prim),
            PyArray1::from_vec(py, u),
            PyArray1::from_vec(py, v),
            PyArray1::from_vec(py, normal).reshape([n, 3])?,
            PyArray1::from_vec(py, front),
        ))
    }

    /// Whether each ray hits anything with `t` in `[t_min, t_max]`.
    #[pyo3(signature = (rays, t_min, t_max, threads = None))]
    fn occluded<'py>(
        &self,
        py: Python<'py>,
        rays: PyReadonlyArray2<'py, f32>,
        t_min: PyReadonlyArray1<'py, f32>,
        t_max: PyReadonlyArray1<'py, f32>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        let rays = arrays::rays(&rays, &t_min, &t_max)?;
        let pool = arrays::pool(threads)?;
        let mut out = vec![false; rays.len()];
        py.detach(|| match (self.tier, &self.packed) {
            (Tier::Standard, Some(p)) => map_into(pool.as_ref(), &rays, &mut out, |_, r, o| {
                tree::occluded::<f32x8, MollerTrumbore>(p.as_ref(), r, o)
            }),
            (Tier::Exact, _) => map_into(pool.as_ref(), &rays, &mut out, |_, r, o| {
                tree::occluded::<f32x8, Exact>(self.bvh(), r, o)
            }),
            _ => map_into(pool.as_ref(), &rays, &mut out, |_, r, o| {
                tree::occluded::<f32x8, Watertight>(self.bvh(), r, o)
            }),
        });
        Ok(PyArray1::from_vec(py, out))
    }

    /// Every hit of every ray, each triangle once per ray: `(ray, prim, t, u, v)` flat, by ray
    /// then `t` ([`EveryHit`]).
    #[pyo3(signature = (rays, t_min, t_max, threads = None))]
    fn all_hits<'py>(
        &self,
        py: Python<'py>,
        rays: PyReadonlyArray2<'py, f32>,
        t_min: PyReadonlyArray1<'py, f32>,
        t_max: PyReadonlyArray1<'py, f32>,
        threads: Option<usize>,
    ) -> PyResult<EveryHit<'py>> {
        let rays = arrays::rays(&rays, &t_min, &t_max)?;
        let pool = arrays::pool(threads)?;
        let hits = py.detach(|| self.every_hits(&rays, pool.as_ref()));
        Ok((
            PyArray1::from_vec(py, hits.iter().map(|&(i, _)| i as i64).collect()),
            PyArray1::from_vec(py, hits.iter().map(|(_, h)| i64::from(h.prim)).collect()),
            PyArray1::from_vec(py, hits.iter().map(|(_, h)| h.t).collect()),
            PyArray1::from_vec(py, hits.iter().map(|(_, h)| h.u).collect()),
            PyArray1::from_vec(py, hits.iter().map(|(_, h)| h.v).collect()),
        ))
    }

    /// How many triangles each ray crosses in `(t_min, t_max)`, exactly: a ray through a
    /// shared edge or vertex crosses one triangle there, once.
    #[pyo3(signature = (rays, t_min, t_max, threads = None))]
    fn crossings<'py>(
        &self,
        py: Python<'py>,
        rays: PyReadonlyArray2<'py, f32>,
        t_min: PyReadonlyArray1<'py, f32>,
        t_max: PyReadonlyArray1<'py, f32>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<u32>>> {
        let rays = arrays::rays(&rays, &t_min, &t_max)?;
        let pool = arrays::pool(threads)?;
        let mut out = vec![0u32; rays.len()];
        let bvh = self.bvh();
        py.detach(|| {
            map_into(pool.as_ref(), &rays, &mut out, |_, r, o| {
                for (ray, o) in r.iter().zip(o) {
                    *o = tree::crossings_ray::<f32x8>(bvh, ray);
                }
            })
        });
        Ok(PyArray1::from_vec(py, out))
    }

    /// Whether each point is inside the closed mesh, exactly (a point on the surface as moved
    /// an infinitesimal step along +x, then +y, then +z). Raises `ValueError` for a mesh that is
    /// not closed.
    #[pyo3(signature = (points, threads = None))]
    fn contains<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f32>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        self.on_solid(py, &points, threads, false, tree::contains::<f32x8>)
    }

    /// The winding number of the closed mesh around each point (1 inside an outward-oriented
    /// mesh, 0 outside). Raises `ValueError` for a mesh that is not closed.
    #[pyo3(signature = (points, threads = None))]
    fn winding_number<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f32>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<i32>>> {
        self.on_solid(py, &points, threads, 0, tree::winding_number::<f32x8>)
    }

    /// The generalized winding number of the mesh at each point (any mesh: open, non-manifold or
    /// self-intersecting; 1 inside and 0 outside a closed, outward-oriented one, ½ on its
    /// surface), within `tolerance` of the exact sum of solid angles (plus f64 rounding). NaN
    /// for a non-finite point. Raises `ValueError` for a negative or NaN tolerance.
    #[pyo3(signature = (points, tolerance = 1e-3, threads = None))]
    fn generalized_winding_number<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f32>,
        tolerance: f64,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        if tolerance.is_nan() || tolerance < 0.0 {
            return Err(PyValueError::new_err(format!(
                "tolerance must be zero or positive, not {tolerance}"
            )));
        }
        let winding = WindingTree::new(self.bvh());
        let out = arrays::per_point(py, &points, threads, f64::NAN, |p| {
            tree::generalized_winding_number(&winding, p, tolerance)
        })?;
        Ok(PyArray1::from_vec(py, out))
    }

    /// The faces that meet the closed box `[lo, hi]`, ascending (int64 indices).
    fn overlapping<'py>(
        &self,
        py: Python<'py>,
        lo: [f32; 3],
        hi: [f32; 3],
    ) -> Bound<'py, PyArray1<i64>> {
        let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
        let mut ids: Vec<i64> = Vec::new();
        let bvh = self.bvh();
        py.detach(|| {
            arrays::pages(
                |after, page| tree::overlapping(bvh, lo, hi, after, page),
                |id: u32| ids.push(i64::from(id)),
            )
        });
        PyArray1::from_vec(py, ids)
    }

    /// The signed distance from each point to the closed mesh: negative inside (the sign
    /// exact), NaN for a non-finite point. Raises `ValueError` for a mesh that is not closed.
    #[pyo3(signature = (points, threads = None))]
    fn signed_distance<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f32>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        self.on_solid(py, &points, threads, 0.0, tree::signed_distance::<f32x8>)
    }

    /// The nearest point of the mesh to each point within `max_distance`: `(point, distance,
    /// prim, u, v)` ([`NearestPoints`]).
    #[pyo3(signature = (points, max_distance, threads = None))]
    fn closest_points<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f32>,
        max_distance: f32,
        threads: Option<usize>,
    ) -> PyResult<NearestPoints<'py>> {
        let bvh = self.bvh();
        let found = arrays::per_point(py, &points, threads, None, |p| {
            tree::closest_point(bvh, p, max_distance)
        })?;
        let n = found.len();
        let mut point = vec![f32::NAN; 3 * n];
        let (mut dist, mut prim) = (vec![f32::INFINITY; n], vec![-1i64; n]);
        let (mut u, mut v) = (vec![0f32; n], vec![0f32; n]);
        for (i, h) in found.iter().enumerate() {
            let Some(h) = h else { continue };
            point[3 * i..3 * i + 3].copy_from_slice(&h.point.to_array());
            (dist[i], prim[i], u[i], v[i]) = (h.dist, i64::from(h.prim), h.u, h.v);
        }
        Ok((
            PyArray1::from_vec(py, point).reshape([n, 3])?,
            PyArray1::from_vec(py, dist),
            PyArray1::from_vec(py, prim),
            PyArray1::from_vec(py, u),
            PyArray1::from_vec(py, v),
        ))
    }

    /// The `k` faces nearest to each point within `radius` (inclusive), nearest first (equal
    /// distances by face index), each face once ([`NearestFaces`]). Raises `ValueError` for a
    /// `k` above the face count or a NaN or negative radius.
    #[pyo3(signature = (points, k, radius, threads = None))]
    fn nearest_within<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f32>,
        k: usize,
        radius: f32,
        threads: Option<usize>,
    ) -> PyResult<NearestFaces<'py>> {
        if k > self.tris().len() {
            return Err(PyValueError::new_err(format!(
                "k must be at most the face count {}, not {k}",
                self.tris().len()
            )));
        }
        if radius.is_nan() || radius < 0.0 {
            return Err(PyValueError::new_err(format!(
                "radius must be zero or positive, not {radius}"
            )));
        }
        let bvh = self.bvh();
        let found = arrays::per_point(py, &points, threads, (Vec::new(), false), |p| {
            let mut out = vec![tree::PointHit::default(); k];
            let got = tree::nearest_within(bvh, p, radius, &mut out);
            out.truncate(got.stored);
            (out, got.complete)
        })?;
        let n = found.len();
        let (mut dist, mut prim) = (vec![f32::INFINITY; n * k], vec![-1i64; n * k]);
        let mut complete = vec![false; n];
        for (i, (hits, whole)) in found.iter().enumerate() {
            for (j, h) in hits.iter().enumerate() {
                (dist[i * k + j], prim[i * k + j]) = (h.dist, i64::from(h.prim));
            }
            complete[i] = *whole;
        }
        Ok((
            PyArray1::from_vec(py, dist).reshape([n, k])?,
            PyArray1::from_vec(py, prim).reshape([n, k])?,
            PyArray1::from_vec(py, complete),
        ))
    }
}

impl Mesh {
    /// `f` of the closed mesh and every point, spread over threads without the GIL; a
    /// `ValueError` for a mesh that is not closed.
    fn on_solid<'py, T: Clone + Send + numpy::Element>(
        &self,
        py: Python<'py>,
        points: &PyReadonlyArray2<'_, f32>,
        threads: Option<usize>,
        init: T,
        f: impl Fn(Solid<'_>, Vec3) -> T + Sync,
    ) -> PyResult<Bound<'py, PyArray1<T>>> {
        let solid = self.solid()?;
        let out = arrays::per_point(py, points, threads, init, |p| f(solid, p))?;
        Ok(PyArray1::from_vec(py, out))
    }
}
