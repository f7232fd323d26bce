//! Fast tier: textbook Möller-Trumbore with fused multiply-adds and a refined reciprocal.
//!
//! # Accuracy contract (fast tier)
//! - **Not** bit-identical across builds or widths: `mul_add` fuses only on FMA builds and the
//!   reciprocal is `wide`'s x86 estimate plus one Newton step (see [`crate::lanes::FastLanes`]).
//!   Its contract is an error bound, measured against the exact oracle (see the accuracy report):
//!   `|t − t_exact| ≤ 32·ε·max(|t|, reach)/|cos θ|` (the standard tier's form with 4× the
//!   constant; measured at most 11.4, p99 37 ulp on random cases, on SSE2 and on AVX-512 builds).
//! - Not watertight: measured 2–5 % of rays escape closed meshes near the origin.
//! - Not watertight; hit/miss can differ from the standard tier within rounding of an edge.
//! - Reported hits always have finite `t ∈ [t_min, t_max]`; bad input is a miss.

use crate::kernel::{t_in_range, LanesHit};
use crate::lanes::{FastLanes, LaneMask};
use crate::ray::{PackedTriangle, RayLanes};
use crate::vec3::V3;

/// `a·b + c·d` with one fused step.
#[inline(always)]
fn dot<L: FastLanes>(a: V3<L>, b: V3<L>) -> L {
    a.x.mul_add(b.x, a.y.mul_add(b.y, a.z * b.z))
}

/// Cross product with one fused step per component.
#[inline(always)]
fn cross<L: FastLanes>(a: V3<L>, b: V3<L>) -> V3<L> {
    V3::new(
        a.y.mul_add(b.z, -(a.z * b.y)),
        a.z.mul_add(b.x, -(a.x * b.z)),
        a.x.mul_add(b.y, -(a.y * b.x)),
    )
}

/// Tests every lane of `ray` against one triangle.
#[inline(always)]
pub fn intersect<L: FastLanes>(ray: &RayLanes<L>, tri: &PackedTriangle) -> LanesHit<L> {
    let (zero, one) = (L::zero(), L::splat(1.0));
    let v0 = V3::<L>::splat(tri.v0);
    let e1 = V3::<L>::splat(tri.e1);
    let e2 = V3::<L>::splat(tri.e2);
    // The 1997 form: p = d × e2, det = e1·p, u = (s·p)/det, q = s × e1, v = (d·q)/det,
    // t = (e2·q)/det, with s = o − v0 and one reciprocal of det.
    let p = cross(ray.dir, e2);
    let det = dot(e1, p);
    let inv = det.recip_refined();
    let s = ray.origin - v0;
    let u = dot(s, p) * inv;
    let mut mask = ray.active & det.ne(zero) & det.is_finite() & u.ge(zero) & u.le(one);
    if mask.none() {
        return LanesHit::miss(mask);
    }
    let q = cross(s, e1);
    let v = dot(ray.dir, q) * inv;
    let t = dot(e2, q) * inv;
    mask = mask & v.ge(zero) & (u + v).le(one) & t_in_range(ray, t);
    LanesHit {
        mask,
        t,
        u,
        v,
        scale: one,
    }
}
