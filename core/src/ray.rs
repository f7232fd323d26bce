//! Rays, primitives and hit records: the scalar types a renderer hands to octoray.

use crate::lanes::{LaneMask, Lanes, Scalar};
use crate::vec3::V3;
use glam::Vec3;

/// A ray `o + t·d` with the parameter interval `[t_min, t_max]` (closed at both ends).
///
/// The direction need not be unit length: `t` is measured in units of `dir`, as on the
/// textbook sheet. A zero, NaN or infinite direction (or origin) is accepted and never hits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin `o`.
    pub origin: Vec3,
    /// Direction `d` (any length).
    pub dir: Vec3,
    /// Smallest accepted `t`.
    pub t_min: f32,
    /// Largest accepted `t`.
    pub t_max: f32,
}

impl Ray {
    /// A ray over `[0, +inf]`.
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        Self::with_range(origin, dir, 0.0, f32::INFINITY)
    }

    /// A ray over `[t_min, t_max]`.
    pub fn with_range(origin: Vec3, dir: Vec3, t_min: f32, t_max: f32) -> Self {
        Self {
            origin,
            dir,
            t_min,
            t_max,
        }
    }

    /// The point `o + t·d` (each component `o + t·d` with two roundings, no FMA).
    pub fn at(&self, t: f32) -> Vec3 {
        Vec3::new(
            self.origin.x + t * self.dir.x,
            self.origin.y + t * self.dir.y,
            self.origin.z + t * self.dir.z,
        )
    }
}

/// A triangle given by its three vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg(feature = "triangle")]
pub struct Triangle {
    /// First vertex (`a1` on the sheet).
    pub v0: Vec3,
    /// Second vertex (`a2`).
    pub v1: Vec3,
    /// Third vertex (`a3`).
    pub v2: Vec3,
}

#[cfg(feature = "triangle")]
impl Triangle {
    /// A triangle from three vertices.
    pub fn new(v0: Vec3, v1: Vec3, v2: Vec3) -> Self {
        Self { v0, v1, v2 }
    }
}

/// A sphere given by centre and radius.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg(feature = "sphere")]
pub struct Sphere {
    /// Centre.
    pub center: Vec3,
    /// Radius; only a finite radius `> 0` can be hit.
    pub radius: f32,
}

#[cfg(feature = "sphere")]
impl Sphere {
    /// A sphere from centre and radius.
    pub fn new(center: Vec3, radius: f32) -> Self {
        Self { center, radius }
    }
}

/// A hit: the ray parameter, the barycentrics of `v1` and `v2` (zero for spheres) and the index
/// of the primitive in the slice that was queried (zero for single-primitive tests).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Ray parameter of the hit, finite and inside `[t_min, t_max]`.
    pub t: f32,
    /// Barycentric weight of `v1` (triangles).
    pub u: f32,
    /// Barycentric weight of `v2` (triangles).
    pub v: f32,
    /// Index of the primitive hit.
    pub prim: u32,
}

/// A triangle in exactly what the Möller-Trumbore kernel reads: `v0`, `e1 = v1 − v0`,
/// `e2 = v2 − v0` (9 floats, 36 bytes, no normal, no index). `bytemuck` casts slices of it to and
/// from `&[f32]`.
///
/// The edges are rounded once to f32 when packed, so a packed triangle's `v1`/`v2` can differ
/// from the input by half an ulp of the edge; the kernels' contracts are stated for the packed
/// triangle.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[cfg(feature = "triangle")]
pub struct PackedTriangle {
    /// First vertex.
    pub v0: [f32; 3],
    /// `v1 − v0`.
    pub e1: [f32; 3],
    /// `v2 − v0`.
    pub e2: [f32; 3],
}

#[cfg(feature = "triangle")]
impl PackedTriangle {
    /// Packs three vertices.
    pub fn new(v0: Vec3, v1: Vec3, v2: Vec3) -> Self {
        Self {
            v0: v0.to_array(),
            e1: (v1 - v0).to_array(),
            e2: (v2 - v0).to_array(),
        }
    }
}

#[cfg(feature = "triangle")]
impl From<Triangle> for PackedTriangle {
    fn from(t: Triangle) -> Self {
        Self::new(t.v0, t.v1, t.v2)
    }
}

/// A triangle as its three vertices (36 bytes, `bytemuck`-castable): what the watertight kernel
/// reads, because watertightness needs the shared vertices themselves, not rounded edges.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[cfg(feature = "triangle")]
pub struct VertexTriangle {
    /// First vertex.
    pub v0: [f32; 3],
    /// Second vertex.
    pub v1: [f32; 3],
    /// Third vertex.
    pub v2: [f32; 3],
}

#[cfg(feature = "triangle")]
impl VertexTriangle {
    /// Stores three vertices.
    pub fn new(v0: Vec3, v1: Vec3, v2: Vec3) -> Self {
        Self {
            v0: v0.to_array(),
            v1: v1.to_array(),
            v2: v2.to_array(),
        }
    }
}

#[cfg(feature = "triangle")]
impl From<Triangle> for VertexTriangle {
    fn from(t: Triangle) -> Self {
        Self::new(t.v0, t.v1, t.v2)
    }
}

/// A sphere in exactly what the sphere kernel reads: centre and squared radius (16 bytes,
/// `bytemuck`-castable).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[cfg(feature = "sphere")]
pub struct PackedSphere {
    /// Centre.
    pub center: [f32; 3],
    /// Squared radius; NaN marks a sphere that can never be hit.
    pub radius_sq: f32,
}

#[cfg(feature = "sphere")]
impl PackedSphere {
    /// Packs a sphere. Usable radii are those whose square is a normal, finite f32: from
    /// [`PackedSphere::MIN_RADIUS`] (≈ 1.08e-19) to [`PackedSphere::MAX_RADIUS`] (≈ 1.84e19). A
    /// radius outside that range, not finite, or not `> 0` is stored as `radius_sq = NaN`, which
    /// every kernel treats as a miss (below the range r² would be 0 or subnormal: a sphere that
    /// silently shrinks or vanishes).
    pub fn new(center: Vec3, radius: f32) -> Self {
        let r2 = radius * radius;
        let radius_sq = if radius > 0.0 && r2.is_finite() && r2 >= f32::MIN_POSITIVE {
            r2
        } else {
            f32::NAN
        };
        Self {
            center: center.to_array(),
            radius_sq,
        }
    }
}

#[cfg(feature = "sphere")]
impl PackedSphere {
    /// The smallest radius whose square is a normal f32 (`√f32::MIN_POSITIVE`, rounded up).
    pub const MIN_RADIUS: f32 = 1.084_202_2e-19;
    /// The largest radius whose square is finite (`√f32::MAX`, rounded down).
    pub const MAX_RADIUS: f32 = 1.844_674_3e19;
}

#[cfg(feature = "sphere")]
impl From<Sphere> for PackedSphere {
    fn from(s: Sphere) -> Self {
        Self::new(s.center, s.radius)
    }
}

/// `L::LANES` rays in structure-of-arrays form plus an active-lane mask. `RayLanes<f32>` is one
/// ray (the form the scalar twins take); the packet crate calls the wide forms `RayPacket`.
/// With f64 lanes the f32 rays are widened exactly.
#[derive(Clone, Copy, Debug)]
pub struct RayLanes<L: Lanes> {
    /// Origins.
    pub origin: V3<L>,
    /// Directions.
    pub dir: V3<L>,
    /// Smallest accepted `t` per lane.
    pub t_min: L,
    /// Largest accepted `t` per lane.
    pub t_max: L,
    /// Lanes that carry a ray; inactive lanes never hit.
    pub active: L::Mask,
}

impl<L: Lanes> RayLanes<L> {
    /// Loads the first `min(rays.len(), L::LANES)` rays; the remaining lanes are inactive (and
    /// hold a zero ray). An empty slice gives a packet with no active lane.
    pub fn load(rays: &[Ray]) -> Self {
        let n = rays.len().min(L::LANES);
        let get = |i: usize, f: fn(&Ray) -> f32| {
            L::Scalar::from_f32(if i < n { f(&rays[i]) } else { 0.0 })
        };
        Self {
            origin: V3::new(
                L::from_fn(|i| get(i, |r| r.origin.x)),
                L::from_fn(|i| get(i, |r| r.origin.y)),
                L::from_fn(|i| get(i, |r| r.origin.z)),
            ),
            dir: V3::new(
                L::from_fn(|i| get(i, |r| r.dir.x)),
                L::from_fn(|i| get(i, |r| r.dir.y)),
                L::from_fn(|i| get(i, |r| r.dir.z)),
            ),
            t_min: L::from_fn(|i| get(i, |r| r.t_min)),
            t_max: L::from_fn(|i| get(i, |r| r.t_max)),
            active: L::first_lanes(n),
        }
    }

    /// Number of active lanes.
    pub fn active_count(&self) -> u32 {
        self.active.bitmask().count_ones()
    }
}

impl<L: Lanes> RayLanes<L> {
    /// One ray in lane 0 (with `L = f32` or `f64`: the form the scalar twins take).
    pub fn single(ray: &Ray) -> Self {
        Self::load(core::slice::from_ref(ray))
    }
}

impl<L: Lanes> RayLanes<L> {
    /// `ray` in every lane, every lane active: one ray against `L::LANES` primitives at once.
    #[inline(always)]
    pub fn broadcast(ray: &Ray) -> Self {
        let s = |x: f32| L::splat(x);
        Self {
            origin: V3::new(s(ray.origin.x), s(ray.origin.y), s(ray.origin.z)),
            dir: V3::new(s(ray.dir.x), s(ray.dir.y), s(ray.dir.z)),
            t_min: s(ray.t_min),
            t_max: s(ray.t_max),
            active: L::first_lanes(L::LANES),
        }
    }

    /// Lane `i`'s ray in every lane (exact: no rounding, also for f64 lanes), every lane active.
    #[inline(always)]
    pub fn broadcast_lane(&self, i: usize) -> Self {
        let s = |x: L| L::splat_scalar(x.lane(i));
        Self {
            origin: V3::new(s(self.origin.x), s(self.origin.y), s(self.origin.z)),
            dir: V3::new(s(self.dir.x), s(self.dir.y), s(self.dir.z)),
            t_min: s(self.t_min),
            t_max: s(self.t_max),
            active: L::first_lanes(L::LANES),
        }
    }

    /// Lane `i` as a scalar ray (f64 lanes rounded to f32).
    pub fn ray(&self, i: usize) -> Ray {
        let f = |x: L| x.lane(i).to_f32();
        Ray::with_range(
            Vec3::new(f(self.origin.x), f(self.origin.y), f(self.origin.z)),
            Vec3::new(f(self.dir.x), f(self.dir.y), f(self.dir.z)),
            f(self.t_min),
            f(self.t_max),
        )
    }
}
