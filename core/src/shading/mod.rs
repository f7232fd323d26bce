//! What a shading step asks of a hit, for every primitive, computed only on request: the hit
//! point, the unit geometric normal facing the ray, and conservatively offset origins for rays
//! that leave the surface (see [`offset`]).
//!
//! [`Shade::surface`] is the one entry point: triangles ([`VertexTriangle`] for the watertight
//! tier, [`PackedTriangle`] for the Möller-Trumbore tiers) and spheres ([`PackedSphere`]) answer
//! it the same way, so a renderer shades every hit with one call.

pub mod offset;

use crate::hit::Hit;
use crate::prim::Ray;
#[cfg(feature = "sphere")]
use crate::prim::{PackedSphere, Sphere};
#[cfg(feature = "triangle")]
use crate::prim::{PackedTriangle, VertexTriangle};
use glam::Vec3;
use offset::offset_ray_origin;

/// Surface data of a hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Surface {
    /// The hit point (from the barycentrics for triangles; projected onto the sphere for
    /// spheres).
    pub point: Vec3,
    /// Componentwise error bound of `point`, as [`offset::offset_ray_origin`] takes it.
    pub error: Vec3,
    /// Unit geometric normal, turned to face the incoming ray (`n·d ≤ 0`): finite and of unit
    /// length for every finite primitive a kernel reports a hit on, whatever its scale; zero only
    /// for a degenerate or non-finite one.
    pub normal: Vec3,
    /// Whether the ray met the primitive's front: the side its own normal points to (a
    /// triangle's `(v1 − v0) × (v2 − v0)`, counter-clockwise seen from the front; a sphere's
    /// outside). `false` when [`Surface::normal`] had to be turned to face the ray: a ray
    /// leaving a closed mesh or a sphere, which a refracting material reads to pick its index.
    /// A ray in the plane of the surface (`n·d = 0`) counts as meeting the front.
    pub front_face: bool,
}

impl Surface {
    /// Surface data from a hit point, its error bound and the primitive's geometric normal (any
    /// length, any finite magnitude, pointing to its front): the normal is normalised
    /// ([`unit_vector`]) and turned to face `ray`, and [`Surface::front_face`] says whether it
    /// was already facing it.
    pub fn new(ray: &Ray, point: Vec3, error: Vec3, normal: Vec3) -> Self {
        Self::facing(ray, point, error, unit_vector(wide::of(normal)))
    }

    /// [`Surface::new`] with the normal already of unit length (or zero).
    fn facing(ray: &Ray, point: Vec3, error: Vec3, unit_normal: Vec3) -> Self {
        // In f64: n·d of a huge direction could overflow f32.
        let back_face = wide::dot(wide::of(unit_normal), wide::of(ray.dir)) > 0.0;
        let front_face = !back_face;
        Self {
            point,
            error,
            normal: if front_face {
                unit_normal
            } else {
                -unit_normal
            },
            front_face,
        }
    }

    /// The origin for a ray leaving the surface in direction `w`, on `w`'s side of it
    /// ([`offset::offset_ray_origin`]); computed on request, so a shader pays only for the
    /// origins it spawns.
    pub fn spawn(&self, w: Vec3) -> Vec3 {
        offset_ray_origin(self.point, self.error, self.normal, w)
    }

    /// Origin for rays leaving on the side the ray came from (reflection, shadow rays towards
    /// that side).
    pub fn spawn_front(&self) -> Vec3 {
        self.spawn(self.normal)
    }

    /// Origin for rays continuing through the surface (refraction).
    pub fn spawn_back(&self) -> Vec3 {
        self.spawn(-self.normal)
    }
}

/// `v / |v|` rounded to f32, or zero when `v` is zero or not finite. In f64: the squared length
/// of any vector of f32-range components (or of products of two, as a cross product of f32 edges)
/// is a normal f64, where in f32 it overflows past ~1.8e19 and underflows below ~1e-19.
pub fn unit_vector(v: [f64; 3]) -> Vec3 {
    let len = wide::length(v);
    if !(len > 0.0 && len.is_finite()) {
        return Vec3::ZERO;
    }
    wide::narrow(v.map(|x| x / len))
}

/// The few f64 vector operations the shading step needs, on `[f64; 3]` (so that glam's f64
/// types, a feature in some of the glam versions octoray accepts, are not required).
// The triangle step uses `cross`, the sphere step `add` and `scale`: a single-primitive build
// leaves the other's unused.
#[cfg_attr(not(all(feature = "triangle", feature = "sphere")), allow(dead_code))]
pub(crate) mod wide {
    use glam::Vec3;
    /// `v` widened exactly.
    pub fn of(v: Vec3) -> [f64; 3] {
        v.to_array().map(f64::from)
    }
    /// Rounded to f32.
    pub fn narrow(v: [f64; 3]) -> Vec3 {
        Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
    }
    pub fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
    pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
    }
    pub fn scale(a: [f64; 3], k: f64) -> [f64; 3] {
        a.map(|x| x * k)
    }
    pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }
    pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }
    pub fn length(a: [f64; 3]) -> f64 {
        libm::sqrt(dot(a, a))
    }
}

/// A primitive layout that can describe the surface at a hit on it.
pub trait Shade {
    /// Surface data for `hit`, a hit of `ray` on `self` (its `t`, `u`, `v`; `prim` is not read).
    fn surface(&self, ray: &Ray, hit: &Hit) -> Surface;
}

#[cfg(feature = "triangle")]
impl Shade for VertexTriangle {
    fn surface(&self, ray: &Ray, hit: &Hit) -> Surface {
        let (p, err) = offset::triangle_hit_point(self, hit.u, hit.v);
        // The edges and their cross product in f64: no f32 overflow or underflow at any scale.
        let [v0, v1, v2] = self.vertices().map(wide::of);
        let n = wide::cross(wide::sub(v1, v0), wide::sub(v2, v0));
        Surface::facing(ray, p, err, unit_vector(n))
    }
}

/// The triangle `v0, v0 + e1, v0 + e2` the packed form describes.
#[cfg(feature = "triangle")]
impl Shade for PackedTriangle {
    fn surface(&self, ray: &Ray, hit: &Hit) -> Surface {
        let v0 = Vec3::from(self.v0);
        let vt = VertexTriangle::new(v0, v0 + Vec3::from(self.e1), v0 + Vec3::from(self.e2));
        vt.surface(ray, hit)
    }
}

/// The normal is the direction from the centre to the hit point, in f64 before the point is
/// rounded. The radius is `√radius_sq` rounded to f32,
/// within an ulp of the radius that was packed, far inside the point's error bound.
#[cfg(feature = "sphere")]
impl Shade for PackedSphere {
    fn surface(&self, ray: &Ray, hit: &Hit) -> Surface {
        Sphere::new(Vec3::from(self.center), libm::sqrtf(self.radius_sq)).surface(ray, hit)
    }
}

#[cfg(feature = "sphere")]
impl Shade for Sphere {
    fn surface(&self, ray: &Ray, hit: &Hit) -> Surface {
        let (p, err, outward) = offset::sphere_hit(ray, hit.t, self.center, self.radius);
        Surface::facing(ray, p, err, unit_vector(outward))
    }
}
