//! Queries over slices of primitives, generic over lane width: closest hit and any hit
//! (occlusion). `L = f32` gives the scalar twins of the packet queries, with the same selection
//! rules, so primitive indices agree lane by lane.

use crate::lanes::{LaneMask, Lanes};
use crate::ray::{Hit, PackedSphere, PackedTriangle, RayLanes};
use crate::{moller_trumbore, sphere_stable};

/// Per-lane closest hit over a slice of primitives.
#[derive(Clone, Copy, Debug)]
pub struct ClosestHit<L: Lanes> {
    /// Lanes that hit something.
    pub mask: L::Mask,
    /// Ray parameter of the closest hit.
    pub t: L,
    /// Barycentric weight of `v1` (triangles; zero for spheres).
    pub u: L,
    /// Barycentric weight of `v2` (triangles; zero for spheres).
    pub v: L,
    /// Index of the closest primitive in the queried slice.
    pub prim: L::Index,
}

impl<L: Lanes> ClosestHit<L> {
    fn miss() -> Self {
        Self {
            mask: L::first_lanes(0),
            t: L::zero(),
            u: L::zero(),
            v: L::zero(),
            prim: L::splat_index(0),
        }
    }

    /// Lane `i` as a scalar hit record, `None` where that lane missed.
    pub fn lane(&self, i: usize) -> Option<Hit> {
        ((self.mask.bitmask() >> i) & 1 == 1).then(|| Hit {
            t: self.t.lane(i),
            u: self.u.lane(i),
            v: self.v.lane(i),
            prim: L::index_lane(self.prim, i),
        })
    }

    /// Records a hit on lanes `m` with primitive `i`; ties keep the earlier primitive because the
    /// caller shrinks `t_max` to the best `t` and only a strictly nearer hit replaces it.
    #[inline(always)]
    fn update(&mut self, m: L::Mask, t: L, u: L, v: L, i: usize) {
        let m = m & (!self.mask | t.lt(self.t));
        self.t = L::select(m, t, self.t);
        self.u = L::select(m, u, self.u);
        self.v = L::select(m, v, self.v);
        self.prim = L::select_index(m, L::splat_index(i as u32), self.prim);
        self.mask = self.mask | m;
    }
}

/// Closest triangle hit per lane (Möller-Trumbore, standard tier). Ties in `t` go to the lower
/// index. Primitive indices are `u32`: slices longer than `u32::MAX` are not supported.
pub fn closest_triangle<L: Lanes>(ray: &RayLanes<L>, tris: &[PackedTriangle]) -> ClosestHit<L> {
    let mut ray = *ray;
    let mut best = ClosestHit::miss();
    for (i, tri) in tris.iter().enumerate() {
        let h = moller_trumbore::intersect(&ray, tri);
        if h.mask.any() {
            best.update(h.mask, h.t, h.u, h.v, i);
            ray.t_max = L::select(best.mask, best.t, ray.t_max);
        }
    }
    best
}

/// Lanes whose ray hits any triangle in `[t_min, t_max]` (occlusion). Stops as soon as every
/// active lane is occluded.
pub fn any_triangle<L: Lanes>(ray: &RayLanes<L>, tris: &[PackedTriangle]) -> L::Mask {
    let mut hit = L::first_lanes(0);
    for tri in tris {
        hit = hit | moller_trumbore::intersect(ray, tri).mask;
        if (hit | !ray.active).all() {
            break;
        }
    }
    hit
}

/// Closest sphere hit per lane (stable sphere kernel). Ties in `t` go to the lower index.
pub fn closest_sphere<L: Lanes>(ray: &RayLanes<L>, spheres: &[PackedSphere]) -> ClosestHit<L> {
    let mut ray = *ray;
    let mut best = ClosestHit::miss();
    for (i, s) in spheres.iter().enumerate() {
        let h = sphere_stable::intersect(&ray, s);
        if h.mask.any() {
            best.update(h.mask, h.t, L::zero(), L::zero(), i);
            ray.t_max = L::select(best.mask, best.t, ray.t_max);
        }
    }
    best
}

/// Lanes whose ray hits any sphere in `[t_min, t_max]` (occlusion), stopping early when every
/// active lane is occluded.
pub fn any_sphere<L: Lanes>(ray: &RayLanes<L>, spheres: &[PackedSphere]) -> L::Mask {
    let mut hit = L::first_lanes(0);
    for s in spheres {
        hit = hit | sphere_stable::intersect(ray, s).mask;
        if (hit | !ray.active).all() {
            break;
        }
    }
    hit
}
