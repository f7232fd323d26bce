//! Fast tier: textbook Möller-Trumbore with fused multiply-adds and a refined reciprocal.
//!
//! # Accuracy contract (fast tier)
//! - **Not** bit-identical across builds or widths: `mul_add` fuses only on FMA builds and the
//!   reciprocal is `wide`'s x86 estimate plus one Newton step (see [`crate::lanes::FastLanes`]).
//!   Its contract is an error bound, measured against the exact oracle (see the accuracy report):
//!   `|t − t_exact| ≤ 32·ε·max(|t|, reach)/|cos θ|` (the standard tier's form with 4× the
//!   constant; measured at most 11.4, p99 37 ulp on random cases, on SSE2 and on AVX-512 builds).
//! - Not watertight: 9.920 % (report: `fast, 8 lanes`, crack rate) of the trade report's crack
//!   rays escape closed meshes near the origin, on the build the report names (FMA); the rate
//!   differs by build, because fusing changes the rounding.
//! - Not watertight; hit/miss can differ from the standard tier within rounding of an edge.
//! - Reported hits always have finite `t ∈ [t_min, t_max]`; bad input is a miss.
//! - Zero-area triangles, rays within ~1e-6 rad of a triangle's plane (`|det| ≤ 8ε·|e1|₁·|d|₁·
//!   |e2|₁`, where `det` is rounding noise) and `|det| ≥ 2¹²⁶` (where x86's reciprocal estimate
//!   is 0) are misses: without that test the 1997 form reports hits on degenerate triangles and
//!   at `t = ±0` on huge ones.

use crate::hit::{t_in_range, LanesHit};
use crate::lanes::V3;
use crate::lanes::{FastLanes, LaneMask};
use crate::prim::{EdgeLanes, Primitive};
use crate::prim::{PackedTriangle, RayLanes};

/// `8ε`: the multiple of `|e1|₁·|d|₁·|e2|₁` below which `det` is rounding noise.
const DET_NOISE: f32 = 8.0 / 16_777_216.0;

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
    intersect_lanes(ray, &tri.splat())
}

/// Tests lane `i` of `ray` against lane `i` of `tri`.
#[inline(always)]
pub fn intersect_lanes<L: FastLanes>(ray: &RayLanes<L>, tri: &EdgeLanes<L>) -> LanesHit<L> {
    let (zero, one) = (L::zero(), L::splat(1.0));
    let (v0, e1, e2) = (tri.v0, tri.e1, tri.e2);
    // The 1997 form: p = d × e2, det = e1·p, u = (s·p)/det, q = s × e1, v = (d·q)/det,
    // t = (e2·q)/det, with s = o − v0 and one reciprocal of det.
    let p = cross(ray.dir, e2);
    let det = dot(e1, p);
    // det is rounding noise when it is below its own error bound, ≲ 2ε·|e1|·|d|·|e2| (L1 norms):
    // a zero-area triangle or a ray within ~1e-6 rad of its plane. Such lanes are misses, or
    // noise over noise would report hits anywhere along the ray.
    let norm1 = |v: V3<L>| v.x.abs() + v.y.abs() + v.z.abs();
    let det_noise = L::splat(DET_NOISE) * norm1(e1) * (norm1(ray.dir) * norm1(e2));
    let inv = det.recip_refined();
    let s = ray.origin - v0;
    let u = dot(s, p) * inv;
    // x86's reciprocal estimate is 0 for |det| ≥ 2¹²⁶ (and inf for subnormal det): both would
    // turn u, v, t into ±0 or NaN, so they are misses too.
    let mut mask = ray.active
        & det.abs().gt(det_noise)
        & det.is_finite()
        & inv.is_finite()
        & inv.ne(zero)
        & u.ge(zero)
        & u.le(one);
    if mask.none() {
        return LanesHit::miss(mask);
    }
    let q = cross(s, e1);
    let v = dot(ray.dir, q) * inv;
    let t = dot(e2, q) * inv + zero;
    mask = mask & v.ge(zero) & (u + v).le(one) & t_in_range(ray, t);
    LanesHit {
        mask,
        t,
        u,
        v,
        scale: one,
    }
}
