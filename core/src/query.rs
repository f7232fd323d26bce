//! Queries over slices of primitives, generic over lane width and tier. Each computes only what
//! is asked:
//!
//! | query | answers | cost beyond the kernel |
//! |---|---|---|
//! | [`occluded`] | a lane mask (occlusion, shadow rays) | none; stops when every lane is occluded |
//! | [`closest_t`] | mask and nearest `t` | one blend per hit |
//! | [`closest`] | `t`, barycentrics, primitive index | five blends per hit, two divisions per query |
//! | [`crate::shading`] | normal and spawn points, for the hits you shade | per hit, scalar |
//!
//! Back-face culling is a kernel choice ([`crate::kernels::MollerTrumboreCulled`],
//! [`crate::kernels::WatertightCulled`]). `L = f32` gives the scalar twins of the packet queries,
//! with the same selection rules, so primitive indices agree lane by lane; every query agrees
//! bit for bit with [`closest`] on what they share (tested).
//!
//! ```
//! # #[cfg(feature = "triangle")] {
//! use octoray_core::glam::Vec3;
//! use octoray_core::query::{occluded, closest, closest_t};
//! use octoray_core::kernels::{MollerTrumbore, MollerTrumboreCulled};
//! use octoray_core::lanes::LaneMask;
//! use octoray_core::prim::{PackedTriangle, Ray, RayLanes};
//!
//! let v = Vec3::new;
//! // Two parallel triangles facing +z at z = 0 and z = -1.
//! let tris = [
//!     PackedTriangle::new(v(0.0, 0.0, -1.0), v(1.0, 0.0, -1.0), v(0.0, 1.0, -1.0)),
//!     PackedTriangle::new(v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)),
//! ];
//! let down = RayLanes::<f32>::single(&Ray::new(v(0.2, 0.2, 1.0), v(0.0, 0.0, -1.0)));
//! let up = RayLanes::<f32>::single(&Ray::new(v(0.2, 0.2, -2.0), v(0.0, 0.0, 1.0)));
//!
//! // One ray (`L = f32`, the scalar twin); `L = f32x8` in octoray-packet traces eight.
//! assert!(occluded::<_, MollerTrumbore>(&down, &tris));
//! let (mask, t) = closest_t::<_, MollerTrumbore>(&down, &tris);
//! assert_eq!((mask, t), (true, 1.0));
//! let full = closest::<_, MollerTrumbore>(&down, &tris).lane(0).unwrap();
//! assert_eq!((full.t, full.prim), (1.0, 1)); // the nearer triangle, index 1
//! // Seen from below, both are back faces: culled, nothing is hit.
//! assert_eq!(closest::<_, MollerTrumboreCulled>(&up, &tris).lane(0), None);
//! assert!(closest::<_, MollerTrumbore>(&up, &tris).lane(0).is_some());
//! # }
//! ```

use crate::hit::Hit;
use crate::kernels::Kernel;
use crate::lanes::{LaneMask, Lanes, Scalar};
use crate::prim::RayLanes;

/// Per-lane closest hit over a slice of primitives (barycentrics already divided).
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
    /// Its geometry in a scene ([`Hit::geom`]; 0 outside a scene).
    pub geom: L::Index,
    /// The instance ([`Hit::inst`]; 0 outside a scene).
    pub inst: L::Index,
}

impl<L: Lanes> ClosestHit<L> {
    fn miss() -> Self {
        Self {
            mask: L::first_lanes(0),
            t: L::zero(),
            u: L::zero(),
            v: L::zero(),
            prim: L::splat_index(0),
            geom: L::splat_index(0),
            inst: L::splat_index(0),
        }
    }

    /// Lane `i` as a scalar hit record (f64 lanes rounded to f32), `None` where that lane missed
    /// and for every `i ≥ L::LANES` (there is no such lane).
    pub fn lane(&self, i: usize) -> Option<Hit> {
        (i < L::LANES && (self.mask.bitmask() >> i) & 1 == 1).then(|| Hit {
            t: self.t.lane(i).to_f32(),
            u: self.u.lane(i).to_f32(),
            v: self.v.lane(i).to_f32(),
            prim: L::index_lane(self.prim, i),
            geom: L::index_lane(self.geom, i),
            inst: L::index_lane(self.inst, i),
        })
    }
}

/// Closest hit per lane with kernel `K`. The kernel sees `t_max` lowered to the best `t` so far,
/// loosened by 2⁻²⁰ relative, as the BVH does (a kernel that decides `t_max` exactly,
/// [`Kernel::EXACT_T_MAX`], sees the caller's `t_max` throughout); a hit replaces the best one
/// only when its `t` is strictly nearer, so ties in `t` go to the lower index.
///
/// # Panics
/// When `prims.len() > u32::MAX`: primitive indices are `u32`, and a longer slice would report
/// wrapped indices.
pub fn closest<L: Lanes, K: Kernel<L>>(ray: &RayLanes<L>, prims: &[K::Prim]) -> ClosestHit<L> {
    check_prim_count(prims.len());
    let pre = K::prepare(ray);
    let t_max = ray.t_max;
    let mut ray = *ray;
    // The running best lives in locals, not in the returned struct: kept there, it is written
    // to memory with masked stores on every hit (slow on AMD; seen in the compiled loop).
    let miss = ClosestHit::<L>::miss();
    let (mut found, mut t, mut u, mut v, mut index) =
        (miss.mask, ray.t_max, miss.u, miss.v, miss.prim);
    let mut scale = L::splat(1.0);
    for (i, prim) in prims.iter().enumerate() {
        let h = K::intersect(&ray, &pre, prim);
        if h.mask.any() {
            let m = h.mask & (!found | h.t.lt(t));
            t = L::select(m, h.t, t);
            u = L::select(m, h.u, u);
            v = L::select(m, h.v, v);
            scale = L::select(m, h.scale, scale);
            index = L::select_index(m, L::splat_index(i as u32), index);
            found = found | m;
            if !K::EXACT_T_MAX {
                // Loosened from the kernel's t (equal to the new best where `m` is set), not from
                // the running best: off the loop-carried chain from one test's t_max to the next.
                ray.t_max = L::select(m, h.t.loosen(t_max), ray.t_max);
            }
        }
    }
    // The barycentrics were carried as numerators: one division for the winner.
    let (u, v) = crate::hit::barycentrics(u, v, scale);
    ClosestHit {
        mask: found,
        t,
        u,
        v,
        prim: index,
        geom: miss.geom,
        inst: miss.inst,
    }
}

/// Panics with a clear message when `n` primitives cannot be indexed by `u32`.
#[inline]
pub(crate) fn check_prim_count(n: usize) {
    assert!(
        n as u64 <= u64::from(u32::MAX),
        "octoray: {n} primitives in one slice; indices are u32 (at most {})",
        u32::MAX
    );
}

/// Closest `t` only, per lane, with kernel `K`: the mask of lanes that hit and their nearest `t`,
/// without barycentrics or primitive index (no per-hit bookkeeping beyond `t`). Lane by lane,
/// `mask` and `t` equal those of [`closest`], bit for bit.
pub fn closest_t<L: Lanes, K: Kernel<L>>(ray: &RayLanes<L>, prims: &[K::Prim]) -> (L::Mask, L) {
    let pre = K::prepare(ray);
    let t_max = ray.t_max;
    let mut ray = *ray;
    let mut found = L::first_lanes(0);
    let mut t = ray.t_max;
    for prim in prims {
        let h = K::intersect(&ray, &pre, prim);
        if h.mask.any() {
            let m = h.mask & (!found | h.t.lt(t));
            t = L::select(m, h.t, t);
            if !K::EXACT_T_MAX {
                ray.t_max = L::select(m, h.t.loosen(t_max), ray.t_max);
            }
            found = found | h.mask;
        }
    }
    (found, t)
}

/// Lanes whose ray hits any primitive in `[t_min, t_max]` with kernel `K` (occlusion). Stops as
/// soon as every active lane is occluded.
pub fn occluded<L: Lanes, K: Kernel<L>>(ray: &RayLanes<L>, prims: &[K::Prim]) -> L::Mask {
    let pre = K::prepare(ray);
    let mut hit = L::first_lanes(0);
    for prim in prims {
        hit = hit | K::intersect(ray, &pre, prim).mask;
        if (hit | !ray.active).all() {
            break;
        }
    }
    hit
}

#[cfg(test)]
mod tests {
    #[test]
    #[should_panic(expected = "indices are u32")]
    fn more_than_u32_max_primitives_is_a_clear_panic() {
        super::check_prim_count(u32::MAX as usize + 1);
    }

    #[test]
    fn u32_max_primitives_are_accepted() {
        super::check_prim_count(u32::MAX as usize);
    }
}
