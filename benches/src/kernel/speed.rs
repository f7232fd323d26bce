//! Every speed entry (our kernels at each tier and width, and the peers), runnable on a prepared
//! workload: the one list the criterion benches, the cycle counts and the trade report share.

use crate::kernel::candidates::{self, FrameTriangle, PlaneTriangle};
use crate::kernel::peers;
use crate::kernel::workload::Workload;
use glam::Vec3A;
use octoray::kernels::{
    Exact, Kernel, MollerTrumbore, MollerTrumboreCulled, NaiveSphere, StableSphere, Watertight,
};
use octoray::lanes::{LaneMask, Lanes};
use octoray::prim::{PackedSphere, PackedTriangle, Ray, RayLanes, Sphere, VertexTriangle};
use octoray::shading::Shade;
use octoray::textbook::{self, InsideTest};
use octoray::{f32x16, f32x4, f32x8, query};
use wide::{f64x4, f64x8};

/// A workload in every layout the entries read, prepared once.
pub struct Prepared {
    /// The workload itself.
    pub w: Workload,
    /// Its triangles in the standard tier's layout.
    pub packed: Vec<PackedTriangle>,
    /// Its triangles as vertices (watertight and exact tiers).
    pub vertex: Vec<VertexTriangle>,
    /// Its triangles as three planes (candidate layout).
    pub planes: Vec<PlaneTriangle>,
    /// Its triangles as a frame (candidate layout).
    pub frames: Vec<FrameTriangle>,
    /// Its spheres.
    pub spheres: Vec<PackedSphere>,
    /// Its triangles for the glam peer.
    pub glam: Vec<[Vec3A; 3]>,
    /// Its rays in 8-ray packets for the ultraviolet peer: origins, directions.
    pub uv_rays: Vec<(ultraviolet::Vec3x8, ultraviolet::Vec3x8)>,
    /// Its triangles for the ultraviolet peer.
    pub uv_tris: Vec<[ultraviolet::Vec3; 3]>,
    /// Its triangles for obvhs.
    pub obvhs: Vec<obvhs::triangle::Triangle>,
    /// Its triangles for the `bvh` crate.
    pub bvh: Vec<[nalgebra::Point3<f32>; 3]>,
    /// Its triangles for parry3d.
    pub parry: Vec<parry3d::shape::Triangle>,
}

impl Prepared {
    /// `w` in every layout.
    pub fn new(w: Workload) -> Self {
        Self {
            packed: w.packed(),
            vertex: w.vertex(),
            planes: w.tris.iter().map(|t| PlaneTriangle::new(*t)).collect(),
            frames: w.tris.iter().map(|t| FrameTriangle::from(*t)).collect(),
            spheres: w.packed_spheres(),
            glam: peers::glam_tris(&w.tris),
            uv_rays: peers::uv_packets(&w.rays),
            uv_tris: peers::uv_tris(&w.tris),
            obvhs: peers::obvhs_tris(&w.tris),
            bvh: peers::bvh_tris(&w.tris),
            parry: peers::parry_tris(&w.tris),
            w,
        }
    }
}

/// What an entry tests.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Prim {
    /// Triangles.
    Triangle,
    /// Spheres.
    Sphere,
}

/// What an entry asks.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Query {
    /// The closest hit.
    Closest,
    /// Any hit.
    Any,
}

/// One benchmarked kernel: a name, what it tests, and a pass over the workload returning the
/// number of rays that hit (so nothing is optimised away and entries can be cross-checked).
#[derive(Clone, Copy)]
pub struct Entry {
    /// The name the reports print.
    pub name: &'static str,
    /// What it tests.
    pub prim: Prim,
    /// What it asks.
    pub query: Query,
    /// An octoray kernel (not a peer or a candidate).
    pub ours: bool,
    /// One pass over the workload: rays that hit.
    pub run: fn(&Prepared) -> u32,
}

fn closest<L: Lanes, K: Kernel<L>>(rays: &[Ray], prims: &[K::Prim]) -> u32 {
    rays.chunks(L::LANES)
        .map(|c| {
            query::closest::<L, K>(&RayLanes::load(c), prims)
                .mask
                .bitmask()
                .count_ones()
        })
        .sum()
}

/// Closest hit plus, for every hit, the surface data a shader asks for (normal, spawn points).
fn closest_surface(p: &Prepared) -> u32 {
    let mut hits = 0;
    for c in p.w.rays.chunks(8) {
        let h = query::closest::<f32x8, MollerTrumbore>(&RayLanes::load(c), &p.packed);
        for (i, r) in c.iter().enumerate() {
            if let Some(hit) = h.lane(i) {
                let s = p.packed[hit.prim as usize].surface(r, &hit);
                hits += u32::from(s.normal.dot(r.dir) <= 0.0);
            }
        }
    }
    hits
}

fn nearest_t<L: Lanes, K: Kernel<L>>(rays: &[Ray], prims: &[K::Prim]) -> u32 {
    rays.chunks(L::LANES)
        .map(|c| {
            query::closest_t::<L, K>(&RayLanes::load(c), prims)
                .0
                .bitmask()
                .count_ones()
        })
        .sum()
}

fn any<L: Lanes, K: Kernel<L>>(rays: &[Ray], prims: &[K::Prim]) -> u32 {
    rays.chunks(L::LANES)
        .map(|c| {
            query::occluded::<L, K>(&RayLanes::load(c), prims)
                .bitmask()
                .count_ones()
        })
        .sum()
}

fn textbook_tris(p: &Prepared) -> u32 {
    let tris: Vec<VertexTriangle> =
        p.w.tris
            .iter()
            .map(|t| VertexTriangle::new(t[0], t[1], t[2]))
            .collect();
    let mut hits = 0;
    for r in &p.w.rays {
        let mut ray = *r;
        let mut hit = false;
        for t in &tris {
            if let Some(h) = textbook::intersect_triangle(&ray, t, InsideTest::Full) {
                ray.t_max = h.t;
                hit = true;
            }
        }
        hits += u32::from(hit);
    }
    hits
}

fn textbook_spheres(p: &Prepared) -> u32 {
    let s: Vec<Sphere> =
        p.w.spheres
            .iter()
            .map(|&(c, r)| Sphere::new(c, r))
            .collect();
    let mut hits = 0;
    for r in &p.w.rays {
        let mut ray = *r;
        let mut hit = false;
        for sp in &s {
            if let Some(h) = textbook::intersect_sphere(&ray, sp) {
                ray.t_max = h.t;
                hit = true;
            }
        }
        hits += u32::from(hit);
    }
    hits
}

macro_rules! e {
    ($name:literal, $prim:ident, $query:ident, $ours:literal, $f:expr) => {
        Entry {
            name: $name,
            prim: Prim::$prim,
            query: Query::$query,
            ours: $ours,
            run: $f,
        }
    };
}

/// Every entry.
pub fn entries() -> Vec<Entry> {
    vec![
        e!("textbook scalar", Triangle, Closest, true, textbook_tris),
        e!("standard x1 (scalar twin)", Triangle, Closest, true, |p| {
            closest::<f32, MollerTrumbore>(&p.w.rays, &p.packed)
        }),
        e!("standard x4", Triangle, Closest, true, |p| closest::<
            f32x4,
            MollerTrumbore,
        >(
            &p.w.rays, &p.packed
        )),
        e!("standard x8", Triangle, Closest, true, |p| closest::<
            f32x8,
            MollerTrumbore,
        >(
            &p.w.rays, &p.packed
        )),
        e!("standard x16", Triangle, Closest, true, |p| closest::<
            f32x16,
            MollerTrumbore,
        >(
            &p.w.rays, &p.packed
        )),
        e!("watertight x1", Triangle, Closest, true, |p| closest::<
            f32,
            Watertight,
        >(
            &p.w.rays, &p.vertex
        )),
        e!("watertight x8", Triangle, Closest, true, |p| closest::<
            f32x8,
            Watertight,
        >(
            &p.w.rays, &p.vertex
        )),
        e!("watertight x16", Triangle, Closest, true, |p| closest::<
            f32x16,
            Watertight,
        >(
            &p.w.rays, &p.vertex
        )),
        e!(
            "exact x1",
            Triangle,
            Closest,
            true,
            |p| closest::<f32, Exact>(&p.w.rays, &p.vertex)
        ),
        e!("exact x8", Triangle, Closest, true, |p| closest::<
            f32x8,
            Exact,
        >(
            &p.w.rays, &p.vertex
        )),
        e!("exact x16", Triangle, Closest, true, |p| closest::<
            f32x16,
            Exact,
        >(
            &p.w.rays, &p.vertex
        )),
        e!("f64 x1", Triangle, Closest, true, |p| closest::<
            f64,
            MollerTrumbore,
        >(
            &p.w.rays, &p.packed
        )),
        e!("f64 x4", Triangle, Closest, true, |p| closest::<
            f64x4,
            MollerTrumbore,
        >(
            &p.w.rays, &p.packed
        )),
        e!("f64 x8", Triangle, Closest, true, |p| closest::<
            f64x8,
            MollerTrumbore,
        >(
            &p.w.rays, &p.packed
        )),
        e!(
            "standard x8 closest+surface",
            Triangle,
            Closest,
            true,
            closest_surface
        ),
        e!(
            "standard x8 culled",
            Triangle,
            Closest,
            true,
            |p| closest::<f32x8, MollerTrumboreCulled>(&p.w.rays, &p.packed)
        ),
        e!("standard x8 closest-t", Triangle, Closest, true, |p| {
            nearest_t::<f32x8, MollerTrumbore>(&p.w.rays, &p.packed)
        }),
        e!("standard x16 closest-t", Triangle, Closest, true, |p| {
            nearest_t::<f32x16, MollerTrumbore>(&p.w.rays, &p.packed)
        }),
        e!("standard x1 any", Triangle, Any, true, |p| any::<
            f32,
            MollerTrumbore,
        >(
            &p.w.rays, &p.packed
        )),
        e!("standard x8 any", Triangle, Any, true, |p| any::<
            f32x8,
            MollerTrumbore,
        >(
            &p.w.rays, &p.packed
        )),
        e!("standard x16 any", Triangle, Any, true, |p| any::<
            f32x16,
            MollerTrumbore,
        >(
            &p.w.rays, &p.packed
        )),
        e!("watertight x8 any", Triangle, Any, true, |p| any::<
            f32x8,
            Watertight,
        >(
            &p.w.rays, &p.vertex
        )),
        e!(
            "exact x8 any",
            Triangle,
            Any,
            true,
            |p| any::<f32x8, Exact>(&p.w.rays, &p.vertex)
        ),
        e!("peer: glam MT scalar", Triangle, Closest, false, |p| {
            peers::glam_closest(&p.w.rays, &p.glam)
        }),
        e!(
            "peer: ultraviolet Vec3x8 MT",
            Triangle,
            Closest,
            false,
            |p| peers::uv_closest(&p.uv_rays, &p.uv_tris)
        ),
        e!(
            "candidate: Havel-Herout planes x8 closest-t",
            Triangle,
            Closest,
            true,
            |p| candidates::count_closest::<f32x8, _>(
                &p.w.rays,
                &p.planes,
                candidates::havel_herout
            )
        ),
        e!(
            "candidate: Baldwin-Weber transform x8 closest-t",
            Triangle,
            Closest,
            true,
            |p| candidates::count_closest::<f32x8, _>(
                &p.w.rays,
                &p.planes,
                candidates::baldwin_weber
            )
        ),
        e!(
            "candidate: Baldwin-Weber at v0 x8 closest-t",
            Triangle,
            Closest,
            true,
            |p| candidates::count_closest::<f32x8, _>(
                &p.w.rays,
                &p.frames,
                candidates::baldwin_weber_v0
            )
        ),
        e!("peer: obvhs", Triangle, Closest, false, |p| {
            peers::obvhs_closest(&p.w.rays, &p.obvhs)
        }),
        e!("peer: bvh", Triangle, Closest, false, |p| {
            peers::bvh_closest(&p.w.rays, &p.bvh)
        }),
        e!("peer: parry3d", Triangle, Closest, false, |p| {
            peers::parry_closest(&p.w.rays, &p.parry)
        }),
        e!(
            "sphere textbook scalar",
            Sphere,
            Closest,
            true,
            textbook_spheres
        ),
        e!("sphere naive x1", Sphere, Closest, true, |p| closest::<
            f32,
            NaiveSphere,
        >(
            &p.w.rays, &p.spheres
        )),
        e!("sphere naive x8", Sphere, Closest, true, |p| closest::<
            f32x8,
            NaiveSphere,
        >(
            &p.w.rays, &p.spheres
        )),
        e!("sphere stable x1", Sphere, Closest, true, |p| closest::<
            f32,
            StableSphere,
        >(
            &p.w.rays, &p.spheres
        )),
        e!("sphere stable x4", Sphere, Closest, true, |p| closest::<
            f32x4,
            StableSphere,
        >(
            &p.w.rays, &p.spheres
        )),
        e!("sphere stable x8", Sphere, Closest, true, |p| closest::<
            f32x8,
            StableSphere,
        >(
            &p.w.rays, &p.spheres
        )),
        e!("sphere stable x16", Sphere, Closest, true, |p| closest::<
            f32x16,
            StableSphere,
        >(
            &p.w.rays, &p.spheres
        )),
        e!("sphere f64 x4", Sphere, Closest, true, |p| closest::<
            f64x4,
            StableSphere,
        >(
            &p.w.rays, &p.spheres
        )),
        e!("sphere stable x8 any", Sphere, Any, true, |p| any::<
            f32x8,
            StableSphere,
        >(
            &p.w.rays, &p.spheres
        )),
        e!(
            "peer: glam naive sphere scalar",
            Sphere,
            Closest,
            false,
            |p| peers::glam_spheres(&p.w.rays, &p.w.spheres)
        ),
        e!("peer: parry3d Ball", Sphere, Closest, false, |p| {
            peers::parry_spheres(&p.w.rays, &p.w.spheres)
        }),
    ]
}

/// The entry called `name`.
pub fn entry(name: &str) -> Option<Entry> {
    entries().into_iter().find(|e| e.name == name)
}
