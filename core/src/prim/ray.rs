//! Rays: one [`Ray`], and [`RayLanes`], `L::LANES` rays in SoA form.

use crate::lanes::{LaneMask, Lanes, Scalar, V3};
use glam::Vec3;

/// A ray `o + t·d` with the parameter interval `[t_min, t_max]` (closed at both ends).
///
/// The direction need not be unit length: `t` is measured in units of `dir`, as on the
/// textbook sheet. A zero, NaN or infinite direction (or origin) is accepted and never hits.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
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

/// `L::LANES` rays in structure-of-arrays form plus an active-lane mask. `RayLanes<f32>` is one
/// ray (the form the scalar twins take); the packet crate calls the wide forms `RayLanes`.
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
        let [ox, oy, oz, dx, dy, dz, t_min, t_max] = L::columns8(n, |i| {
            let r = &rays[i];
            let (o, d) = (r.origin, r.dir);
            [o.x, o.y, o.z, d.x, d.y, d.z, r.t_min, r.t_max]
        });
        Self {
            origin: V3::new(ox, oy, oz),
            dir: V3::new(dx, dy, dz),
            t_min,
            t_max,
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
