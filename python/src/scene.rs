//! `Scene`: triangle meshes and sphere sets placed in the world by instances (affine
//! transforms, masks); batched first hits and occlusion through it.

use crate::arrays::{self, map_into, Bools, F32s, I64s, Rows3};
use crate::tier::Tier;
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2};
use octoray::f32x8;
use octoray::glam::{Affine3A, Mat3, Vec3};
use octoray::hit::Hit;
use octoray::kernels::{Exact, Kernel, MollerTrumbore, NearestPoint, StableSphere, Watertight};
use octoray::parallel::Rayon;
use octoray::prim::{PackedSphere, PackedTriangle, Primitive, Ray, VertexTriangle};
use octoray::scene::{Place, Scene as Built, Trace, Tracer, Transform};
use octoray::shading::Shade;
use octoray::tree::PointHit;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;

/// A geometry's primitives, kept to shade its hits.
enum Shapes {
    /// Each triangle's unit geometric normal.
    Triangles(Vec<[f32; 3]>),
    Spheres(Vec<PackedSphere>),
}

/// The scene in its tier's triangle layout.
enum Layout {
    /// Watertight and exact.
    Vertex(Built<VertexTriangle, PackedSphere>),
    /// Standard.
    Packed(Built<PackedTriangle, PackedSphere>),
}

/// Meshes and sphere sets (geometries) placed by instances; queries after `commit`.
#[pyclass(module = "octoray._octoray")]
pub struct Scene {
    tier: Tier,
    layout: Layout,
    shapes: Vec<Shapes>,
    /// Each instance's world → object map.
    transforms: Vec<Transform>,
}

/// The first hits as arrays: `t` (inf: miss), primitive, geometry and instance (−1: miss), `u`,
/// `v`, the unit geometric normal in world space (0: miss) and whether the ray met the front.
type FirstHits<'py> = (
    F32s<'py>,
    I64s<'py>,
    I64s<'py>,
    I64s<'py>,
    F32s<'py>,
    F32s<'py>,
    Rows3<'py>,
    Bools<'py>,
);

/// Every hit, flat, by ray then hit order: ray index, primitive, geometry, instance, `t`, `u`,
/// `v`.
type EveryHit<'py> = (
    I64s<'py>,
    I64s<'py>,
    I64s<'py>,
    I64s<'py>,
    F32s<'py>,
    F32s<'py>,
    F32s<'py>,
);

/// The closest points: the point, its distance (inf: none within the bound), primitive,
/// geometry and instance (−1: none), `u`, `v`.
type NearestPoints<'py> = (
    Rows3<'py>,
    F32s<'py>,
    I64s<'py>,
    I64s<'py>,
    I64s<'py>,
    F32s<'py>,
    F32s<'py>,
);

/// `$query::<KT>(scene, args…)` with the triangle kernel of `$scene`'s layout and tier.
macro_rules! by_tier {
    ($scene:expr, $query:ident($($arg:expr),*)) => {
        match (&$scene.layout, $scene.tier) {
            (Layout::Packed(s), _) => $query::<MollerTrumbore>(s, $($arg),*),
            (Layout::Vertex(s), Tier::Exact) => $query::<Exact>(s, $($arg),*),
            (Layout::Vertex(s), _) => $query::<Watertight>(s, $($arg),*),
        }
    };
}

/// `query(tracer, rays, masks, out)` over chunks of `rays` (ray `i` under `masks[i]`) through
/// `scene` with triangle tier `KT`, spread over `pool`'s threads; `out` starts as `init`.
fn traced<KT: Kernel<f32x8>, O: Clone + Send>(
    scene: &Built<KT::Prim, PackedSphere>,
    rays: &[Ray],
    masks: &[u32],
    pool: Option<&rayon::ThreadPool>,
    init: O,
    query: impl Fn(&Tracer<'_, f32x8, KT, StableSphere>, &[Ray], &[u32], &mut [O]) + Sync,
) -> Vec<O>
where
    KT::Prim: Primitive,
{
    let tracer = Tracer::<f32x8, KT, StableSphere>::new(scene.as_ref());
    let mut out = vec![init; rays.len()];
    map_into(pool, rays, &mut out, |first, r, o| {
        query(&tracer, r, &masks[first..first + r.len()], o)
    });
    out
}

/// The first hit of every ray through `scene` with triangle tier `KT`, ray `i` under `masks[i]`.
fn first_hits<KT: Kernel<f32x8>>(
    scene: &Built<KT::Prim, PackedSphere>,
    rays: &[Ray],
    masks: &[u32],
    pool: Option<&rayon::ThreadPool>,
) -> Vec<Option<Hit>>
where
    KT::Prim: Primitive,
{
    traced::<KT, _>(scene, rays, masks, pool, None, |t, r, m, o| {
        t.closest(r, m, o)
    })
}

/// Whether every ray through `scene` with triangle tier `KT` hits anything, ray `i` under
/// `masks[i]`.
fn occlusion<KT: Kernel<f32x8>>(
    scene: &Built<KT::Prim, PackedSphere>,
    rays: &[Ray],
    masks: &[u32],
    pool: Option<&rayon::ThreadPool>,
) -> Vec<bool>
where
    KT::Prim: Primitive,
{
    traced::<KT, _>(scene, rays, masks, pool, false, |t, r, m, o| {
        t.occluded(r, m, o)
    })
}

/// Every hit of every ray through `scene` with triangle tier `KT`, ray `i` under `masks[i]`:
/// `(ray, hit)` by ray, then in hit order.
fn every_hit<KT: Kernel<f32x8>>(
    scene: &Built<KT::Prim, PackedSphere>,
    rays: &[Ray],
    masks: &[u32],
    pool: Option<&rayon::ThreadPool>,
) -> Vec<(usize, Hit)>
where
    KT::Prim: Primitive,
{
    let tracer = Tracer::<f32x8, KT, StableSphere>::new(scene.as_ref());
    arrays::collect(pool, rays, |i, ray, out| {
        arrays::paged(i, out, |after, page| {
            tracer.all_hits_ray(ray, masks[i], after, page)
        })
    })
}

/// The nearest point of `scene` to every point within `max_dist`, under `mask`.
fn nearest<KT: Kernel<f32x8>>(
    scene: &Built<KT::Prim, PackedSphere>,
    py: Python<'_>,
    points: &PyReadonlyArray2<'_, f32>,
    (max_dist, mask): (f32, u32),
    threads: Option<usize>,
) -> PyResult<Vec<Option<PointHit>>>
where
    KT::Prim: Primitive + NearestPoint,
{
    let tracer = Tracer::<f32x8, KT, StableSphere>::new(scene.as_ref());
    arrays::per_point(py, points, threads, None, |p| {
        tracer.closest_point(p, max_dist, mask)
    })
}

/// The scene in the vertex layout (watertight and exact tiers), or the `ValueError` a crossing
/// query on a standard-tier scene gets.
fn vertex(layout: &Layout) -> PyResult<&Built<VertexTriangle, PackedSphere>> {
    match layout {
        Layout::Vertex(s) => Ok(s),
        Layout::Packed(_) => Err(PyValueError::new_err(
            "a standard-tier scene has no crossing rule: use tier=\"watertight\" or \"exact\"",
        )),
    }
}

/// The world → object map of an instance placed by `rows`, the object → world matrix's top
/// three rows (12 numbers by rows): a `ValueError` when it is not finite or not invertible.
fn placing(rows: &[f64]) -> PyResult<Transform> {
    // The identity as the library's own (its inverse formed in f64 could carry −0 entries,
    // which are not the identity): rays through it are used as they are.
    const IDENTITY: [f64; 12] = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    if rows == IDENTITY {
        return Ok(Transform::IDENTITY);
    }
    let r = |i: usize, j: usize| rows[4 * i + j] as f32;
    let linear = Mat3::from_cols(
        Vec3::new(r(0, 0), r(1, 0), r(2, 0)),
        Vec3::new(r(0, 1), r(1, 1), r(2, 1)),
        Vec3::new(r(0, 2), r(1, 2), r(2, 2)),
    );
    let place = Affine3A::from_mat3_translation(linear, Vec3::new(r(0, 3), r(1, 3), r(2, 3)));
    Transform::placing(place)
        .ok_or_else(|| PyValueError::new_err("transform is not finite or not invertible"))
}

impl Scene {
    /// The unit geometric normal in world space of hit `h` of world ray `ray`, and whether the
    /// ray met its front. A normal maps by the transpose of the world → object matrix `A`; a
    /// triangle's `(v1 − v0) × (v2 − v0)` in world space also turns with the sign of `det A`.
    fn shade(&self, ray: &Ray, h: &Hit) -> ([f32; 3], bool) {
        let place = &self.transforms[h.inst as usize];
        let (g, triangle) = match &self.shapes[h.geom as usize] {
            Shapes::Triangles(n) => (Vec3::from(n[h.prim as usize]), true),
            Shapes::Spheres(s) => {
                let s = s[h.prim as usize].surface(&place.apply(ray), h);
                (if s.front_face { s.normal } else { -s.normal }, false)
            }
        };
        if place.is_identity() {
            // The object is the world: the mesh's own answer, bit for bit.
            return (g.to_array(), arrays::meets_front(g.to_array(), ray.dir));
        }
        let a = place.rows.map(|r| r.map(f64::from));
        let g = [f64::from(g.x), f64::from(g.y), f64::from(g.z)];
        let mut n = [0.0f64; 3];
        for (j, nj) in n.iter_mut().enumerate() {
            *nj = (0..3).map(|i| a[i][j] * g[i]).sum();
        }
        let det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1])
            - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0])
            + a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
        let len = n.iter().map(|x| x * x).sum::<f64>().sqrt();
        let sign = if triangle && det < 0.0 { -1.0 } else { 1.0 };
        if !(len > 0.0 && len.is_finite()) {
            return ([0.0; 3], true);
        }
        let n = n.map(|x| (sign * x / len) as f32);
        (n, arrays::meets_front(n, ray.dir))
    }

    /// `f` of the committed scene's watertight tracer and every point, spread over threads
    /// without the GIL; a `ValueError` for a standard-tier scene.
    fn on_solids<'py, T: Clone + Send + numpy::Element>(
        &self,
        py: Python<'py>,
        points: &PyReadonlyArray2<'_, f32>,
        threads: Option<usize>,
        init: T,
        f: impl Fn(&Tracer<'_, f32x8, Watertight, StableSphere>, Vec3) -> T + Sync,
    ) -> PyResult<Bound<'py, PyArray1<T>>> {
        self.committed()?;
        let scene = vertex(&self.layout)?;
        let tracer = Tracer::<f32x8, Watertight, StableSphere>::new(scene.as_ref());
        let out = arrays::per_point(py, points, threads, init, |p| f(&tracer, p))?;
        Ok(PyArray1::from_vec(py, out))
    }

    /// A `RuntimeError` unless the scene is committed.
    fn committed(&self) -> PyResult<()> {
        let done = match &self.layout {
            Layout::Vertex(s) => s.is_committed(),
            Layout::Packed(s) => s.is_committed(),
        };
        if done {
            Ok(())
        } else {
            Err(PyRuntimeError::new_err(
                "the scene changed since its last commit: call commit() first",
            ))
        }
    }

    /// Rays, masks and threads of a query, checked.
    fn query(
        rays: &PyReadonlyArray2<'_, f32>,
        t_min: &PyReadonlyArray1<'_, f32>,
        t_max: &PyReadonlyArray1<'_, f32>,
        mask: &PyReadonlyArray1<'_, u32>,
        threads: Option<usize>,
    ) -> PyResult<(Vec<Ray>, Vec<u32>, Option<rayon::ThreadPool>)> {
        let rays = arrays::rays(rays, t_min, t_max)?;
        let masks = arrays::column(mask, rays.len(), "mask")?.to_vec();
        Ok((rays, masks, arrays::pool(threads)?))
    }
}

#[pymethods]
impl Scene {
    /// An empty scene whose triangles are answered with `tier`.
    #[new]
    #[pyo3(signature = (tier = "watertight"))]
    fn new(tier: &str) -> PyResult<Self> {
        let tier = Tier::parse(tier)?;
        let layout = match tier {
            Tier::Standard => Layout::Packed(Built::new()),
            _ => Layout::Vertex(Built::new()),
        };
        Ok(Self {
            tier,
            layout,
            shapes: Vec::new(),
            transforms: Vec::new(),
        })
    }

    /// The tier's name.
    #[getter]
    fn tier(&self) -> &'static str {
        self.tier.name()
    }

    /// Adds a triangle mesh (its BVH built now); returns its geometry index.
    fn add_mesh(
        &mut self,
        py: Python<'_>,
        vertices: PyReadonlyArray2<'_, f32>,
        faces: PyReadonlyArray2<'_, i64>,
    ) -> PyResult<u32> {
        let tris = arrays::triangles(&vertices, &faces)?;
        let layout = &mut self.layout;
        let geom = py
            .detach(|| match layout {
                Layout::Vertex(s) => s.add_triangles(&tris),
                Layout::Packed(s) => s.add_triangles(&arrays::packed(&tris)),
            })
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        self.shapes
            .push(Shapes::Triangles(arrays::unit_normals(&tris)));
        Ok(geom)
    }

    /// Adds spheres, `centers` (n, 3) and `radii` (n,); returns their geometry index.
    fn add_spheres(
        &mut self,
        py: Python<'_>,
        centers: PyReadonlyArray2<'_, f32>,
        radii: PyReadonlyArray1<'_, f32>,
    ) -> PyResult<u32> {
        let c = arrays::points(&centers)?;
        let r = arrays::column(&radii, c.len(), "radii")?;
        let spheres: Vec<PackedSphere> = c
            .iter()
            .zip(r)
            .map(|(&c, &r)| PackedSphere::new(c, r))
            .collect();
        let layout = &mut self.layout;
        let geom = py
            .detach(|| match layout {
                Layout::Vertex(s) => s.add_spheres(&spheres),
                Layout::Packed(s) => s.add_spheres(&spheres),
            })
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        self.shapes.push(Shapes::Spheres(spheres));
        Ok(geom)
    }

    /// Places geometries (one kind; one tree over them) by the object → world matrix `rows`
    /// (its top three rows, 12 numbers by rows) under `mask`; returns the instance index.
    fn add_instance(&mut self, geometries: Vec<u32>, rows: Vec<f64>, mask: u32) -> PyResult<u32> {
        if rows.len() != 12 {
            return Err(PyValueError::new_err(
                "transform must have 12 entries (3 by 4)",
            ));
        }
        let Some(&first) = geometries.first() else {
            return Err(PyValueError::new_err(
                "an instance needs at least one geometry",
            ));
        };
        let n = self.shapes.len();
        let kind = |g: u32| match self.shapes.get(g as usize) {
            Some(Shapes::Triangles(_)) => Ok(0),
            Some(Shapes::Spheres(_)) => Ok(1),
            None => Err(PyValueError::new_err(format!(
                "geometry {g} out of range for {n} geometries"
            ))),
        };
        let k = kind(first)?;
        for &g in &geometries {
            if kind(g)? != k {
                return Err(PyValueError::new_err(
                    "an instance's geometries must all be meshes or all sphere sets",
                ));
            }
        }
        let place = placing(&rows)?;
        if self.transforms.len() >= u32::MAX as usize {
            return Err(PyValueError::new_err("too many instances"));
        }
        let inst = match &mut self.layout {
            Layout::Vertex(s) => s.add_instance(&geometries, place, mask),
            Layout::Packed(s) => s.add_instance(&geometries, place, mask),
        };
        self.transforms.push(place);
        Ok(inst)
    }

    /// Builds the top level over the instances: queries see the scene as it is now.
    fn commit(&mut self, py: Python<'_>) -> PyResult<()> {
        let layout = &mut self.layout;
        // On rayon's threads; the same trees as a single-threaded commit's.
        py.detach(|| match layout {
            Layout::Vertex(s) => s.commit_on(&Rayon),
            Layout::Packed(s) => s.commit_on(&Rayon),
        })
        .map_err(|e| PyValueError::new_err(e.to_string()))
    }

    /// The first hit of every ray under its mask: `(t, prim, geom, inst, u, v, normal, front)`
    /// ([`FirstHits`]).
    #[pyo3(signature = (rays, t_min, t_max, mask, threads = None))]
    fn closest<'py>(
        &self,
        py: Python<'py>,
        rays: PyReadonlyArray2<'py, f32>,
        t_min: PyReadonlyArray1<'py, f32>,
        t_max: PyReadonlyArray1<'py, f32>,
        mask: PyReadonlyArray1<'py, u32>,
        threads: Option<usize>,
    ) -> PyResult<FirstHits<'py>> {
        self.committed()?;
        let (rays, masks, pool) = Self::query(&rays, &t_min, &t_max, &mask, threads)?;
        let pool = pool.as_ref();
        let hits = py.detach(|| by_tier!(self, first_hits(&rays, &masks, pool)));
        let n = rays.len();
        let mut t = vec![f32::INFINITY; n];
        let (mut prim, mut geom, mut inst) = (vec![-1i64; n], vec![-1i64; n], vec![-1i64; n]);
        let (mut u, mut v) = (vec![0f32; n], vec![0f32; n]);
        let (mut normal, mut front) = (vec![0f32; 3 * n], vec![false; n]);
        for (i, (h, ray)) in hits.iter().zip(&rays).enumerate() {
            let Some(h) = h else { continue };
            (t[i], u[i], v[i]) = (h.t, h.u, h.v);
            (prim[i], geom[i], inst[i]) = (h.prim.into(), h.geom.into(), h.inst.into());
            let (nrm, f) = self.shade(ray, h);
            normal[3 * i..3 * i + 3].copy_from_slice(&nrm);
            front[i] = f;
        }
        Ok((
            PyArray1::from_vec(py, t),
            PyArray1::from_vec(py, prim),
            PyArray1::from_vec(py, geom),
            PyArray1::from_vec(py, inst),
            PyArray1::from_vec(py, u),
            PyArray1::from_vec(py, v),
            PyArray1::from_vec(py, normal).reshape([n, 3])?,
            PyArray1::from_vec(py, front),
        ))
    }

    /// Whether each ray hits anything under its mask.
    #[pyo3(signature = (rays, t_min, t_max, mask, threads = None))]
    fn occluded<'py>(
        &self,
        py: Python<'py>,
        rays: PyReadonlyArray2<'py, f32>,
        t_min: PyReadonlyArray1<'py, f32>,
        t_max: PyReadonlyArray1<'py, f32>,
        mask: PyReadonlyArray1<'py, u32>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        self.committed()?;
        let (rays, masks, pool) = Self::query(&rays, &t_min, &t_max, &mask, threads)?;
        let pool = pool.as_ref();
        let out = py.detach(|| by_tier!(self, occlusion(&rays, &masks, pool)));
        Ok(PyArray1::from_vec(py, out))
    }

    /// Every hit of every ray under its mask, each primitive once per ray: `(ray, prim, geom,
    /// inst, t, u, v)` flat, by ray then hit order ([`EveryHit`]).
    #[pyo3(signature = (rays, t_min, t_max, mask, threads = None))]
    fn all_hits<'py>(
        &self,
        py: Python<'py>,
        rays: PyReadonlyArray2<'py, f32>,
        t_min: PyReadonlyArray1<'py, f32>,
        t_max: PyReadonlyArray1<'py, f32>,
        mask: PyReadonlyArray1<'py, u32>,
        threads: Option<usize>,
    ) -> PyResult<EveryHit<'py>> {
        self.committed()?;
        let (rays, masks, pool) = Self::query(&rays, &t_min, &t_max, &mask, threads)?;
        let pool = pool.as_ref();
        let hits = py.detach(|| by_tier!(self, every_hit(&rays, &masks, pool)));
        let ids = |f: fn(&Hit) -> u32| hits.iter().map(|(_, h)| i64::from(f(h))).collect();
        let floats = |f: fn(&Hit) -> f32| hits.iter().map(|(_, h)| f(h)).collect();
        Ok((
            PyArray1::from_vec(py, hits.iter().map(|&(i, _)| i as i64).collect()),
            PyArray1::from_vec(py, ids(|h| h.prim)),
            PyArray1::from_vec(py, ids(|h| h.geom)),
            PyArray1::from_vec(py, ids(|h| h.inst)),
            PyArray1::from_vec(py, floats(|h| h.t)),
            PyArray1::from_vec(py, floats(|h| h.u)),
            PyArray1::from_vec(py, floats(|h| h.v)),
        ))
    }

    /// How many triangles of the instanced meshes each ray crosses in `(t_min, t_max)` under its
    /// mask, exactly (the crossing rule in each instance's object space; spheres do not count).
    /// Raises `ValueError` for a standard-tier scene.
    #[pyo3(signature = (rays, t_min, t_max, mask, threads = None))]
    fn crossings<'py>(
        &self,
        py: Python<'py>,
        rays: PyReadonlyArray2<'py, f32>,
        t_min: PyReadonlyArray1<'py, f32>,
        t_max: PyReadonlyArray1<'py, f32>,
        mask: PyReadonlyArray1<'py, u32>,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<u32>>> {
        self.committed()?;
        let scene = vertex(&self.layout)?;
        let (rays, masks, pool) = Self::query(&rays, &t_min, &t_max, &mask, threads)?;
        let out = py.detach(|| {
            traced::<Watertight, _>(scene, &rays, &masks, pool.as_ref(), 0, |t, r, m, o| {
                for ((ray, &mask), o) in r.iter().zip(m).zip(o) {
                    *o = t.crossings_ray(ray, mask);
                }
            })
        });
        Ok(PyArray1::from_vec(py, out))
    }

    /// Whether each point is inside the instanced closed meshes under `mask` (inside an odd
    /// number of them), exactly for the point as each instance's map carries it. Raises
    /// `ValueError` for a standard-tier scene.
    #[pyo3(signature = (points, mask, threads = None))]
    fn contains<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f32>,
        mask: u32,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<bool>>> {
        self.on_solids(py, &points, threads, false, |t, p| t.contains(p, mask))
    }

    /// The signed distance from each point to the instances under `mask`: to the nearest
    /// primitive, negative inside the closed meshes (the sign exact), NaN for a non-finite
    /// point. Raises `ValueError` for a standard-tier scene.
    #[pyo3(signature = (points, mask, threads = None))]
    fn signed_distance<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f32>,
        mask: u32,
        threads: Option<usize>,
    ) -> PyResult<Bound<'py, PyArray1<f32>>> {
        self.on_solids(py, &points, threads, f32::NAN, |t, p| {
            t.signed_distance(p, mask)
        })
    }

    /// Every primitive of the instances under `mask` that meets the closed world box
    /// `[lo, hi]`, ascending, each once: `(n, 3)` rows of instance path, geometry and primitive.
    fn overlapping<'py>(
        &self,
        py: Python<'py>,
        lo: [f32; 3],
        hi: [f32; 3],
        mask: u32,
    ) -> PyResult<Bound<'py, numpy::PyArray2<i64>>> {
        self.committed()?;
        let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
        let mut rows: Vec<i64> = Vec::new();
        py.detach(|| {
            let mut push = |p: Place| rows.extend([p.inst, p.geom, p.prim].map(i64::from));
            match &self.layout {
                Layout::Packed(s) => arrays::pages(
                    |after, page| s.as_ref().overlapping(lo, hi, mask, after, page),
                    &mut push,
                ),
                Layout::Vertex(s) => arrays::pages(
                    |after, page| s.as_ref().overlapping(lo, hi, mask, after, page),
                    &mut push,
                ),
            }
        });
        let n = rows.len() / 3;
        PyArray1::from_vec(py, rows).reshape([n, 3])
    }

    /// The nearest point of the scene (its instances under `mask`) to each point within
    /// `max_distance`: `(point, distance, prim, geom, inst, u, v)` ([`NearestPoints`]).
    #[pyo3(signature = (points, max_distance, mask, threads = None))]
    fn closest_points<'py>(
        &self,
        py: Python<'py>,
        points: PyReadonlyArray2<'py, f32>,
        max_distance: f32,
        mask: u32,
        threads: Option<usize>,
    ) -> PyResult<NearestPoints<'py>> {
        self.committed()?;
        let query = (max_distance, mask);
        let found = match &self.layout {
            Layout::Packed(s) => nearest::<MollerTrumbore>(s, py, &points, query, threads)?,
            Layout::Vertex(s) => nearest::<Watertight>(s, py, &points, query, threads)?,
        };
        let n = found.len();
        let mut point = vec![f32::NAN; 3 * n];
        let mut dist = vec![f32::INFINITY; n];
        let (mut prim, mut geom, mut inst) = (vec![-1i64; n], vec![-1i64; n], vec![-1i64; n]);
        let (mut u, mut v) = (vec![0f32; n], vec![0f32; n]);
        for (i, h) in found.iter().enumerate() {
            let Some(h) = h else { continue };
            point[3 * i..3 * i + 3].copy_from_slice(&h.point.to_array());
            (dist[i], u[i], v[i]) = (h.dist, h.u, h.v);
            (prim[i], geom[i], inst[i]) = (h.prim.into(), h.geom.into(), h.inst.into());
        }
        Ok((
            PyArray1::from_vec(py, point).reshape([n, 3])?,
            PyArray1::from_vec(py, dist),
            PyArray1::from_vec(py, prim),
            PyArray1::from_vec(py, geom),
            PyArray1::from_vec(py, inst),
            PyArray1::from_vec(py, u),
            PyArray1::from_vec(py, v),
        ))
    }
}
