//! Möller-Trumbore ray-triangle, two-sided, with delayed division: one generic body for every
//! lane width; `L = f32` is the scalar twin.
//!
//! # Guarantees (standard tier)
//! - **Same bits** across `f32`, `f32x4`, `f32x8`, `f32x16` and across builds (SSE2, AVX,
//!   AVX-512): only `+ − × /` and comparisons, in a fixed order (proptested).
//! - `t = (s·Ng)/det` is the plane distance formed from one subtraction and the exact edges, then
//!   one correctly rounded division (the textbook form `(e2·q)/det` loses an order of magnitude
//!   more on grazing rays).
//! - **t error bound:** `|t − t_exact| ≤ 8·ε·max(|t|, reach)/(|cos θ|·sin α)`, with ε = 2⁻²⁴,
//!   `reach = (|o − v0| + |e1| + |e2|)/|d|`, θ the angle between the ray and the normal and α the
//!   triangle's smallest angle. `t` is a plane distance: near t = 0 and at grazing angles its
//!   *relative* error is unbounded.
//! - **Within the box:** `t` is raised to the ray's entry into the triangle's bounding box where
//!   it lies before it (grazing rays, where the bound above exceeds the box's extent along the
//!   ray), which only moves it toward the exact `t`; a ray that leaves that box before `t_min`
//!   is a miss (its exact `t` is before `t_min`). So no BVH box that holds the triangle is
//!   entered after a reported hit on it or left before `t_min`: the walks' culling equals brute
//!   force.
//! - Hit/miss agrees with the exact answer whenever the exact hit point is farther than
//!   `64·ε·|o − v0|/(h·|cos θ|)` (barycentric units, h the smallest height) from every edge.
//! - Reported hits always have finite `t ∈ [t_min, t_max]`, finite `u, v ≥ 0` with `u + v ≲ 1`.
//!
//! # Limits
//! - **Not watertight:** a ray through a shared edge or vertex can miss both neighbours when the
//!   rounded edge functions disagree in sign. Use the watertight tier where that matters.
//! - **Misses by construction:** non-finite inputs, zero directions, zero-area triangles (also
//!   needles whose packed edges are parallel: `|det| ≤ 8ε·|d|₁·|e1|₁·|e2|₁`), rays in or parallel
//!   to the plane (within ~1e-6 rad), products that overflow (coordinates beyond ~1e12) and
//!   products that underflow (`|e1|₁·|e2|₁` or `|d|₁·|e1|₁·|e2|₁` below 2⁻¹⁰⁰ at f32, 2⁻⁹⁹⁶ at
//!   f64: with `|d| = 1`, triangles below ~1e-15).
//! - **Needles:** the computed normal `e1 × e2` is itself off by ε/sin α (a needle 5e7 long and
//!   6e-8 wide gives t = 0 for an exact t of −41).
//! - **Range of the bounds:** every product of the inputs must stay a normal f32. Where
//!   `|d|·|v − o| < 1e-30` (a subnormal or tiny direction) the products `s × d` go subnormal and
//!   `t` loses its relative accuracy (t = 2.0e38 for an exact 4e38 with |d| = 7e-41); hits keep
//!   the shape guarantees above. Normalise directions.
//!
//! # Measured
//! Against the exact oracle (`cargo run --release --example accuracy`): the `t` error at most
//! `4.1·ε·max(|t|, reach)/(|cos θ|·sin α)` over random, edge-aimed, grazing (1e-3…1e-7 rad) and
//! translated (1e2…1e6) cases; p50 0 ulp and p99 23 ulp on random cases.

use crate::hit::{t_in_range, within_box, LanesHit};
use crate::lanes::V3;
use crate::lanes::{LaneMask, Lanes, Scalar};
use crate::prim::{EdgeLanes, Primitive};
use crate::prim::{PackedTriangle, RayLanes};

/// `8ε`: the multiple of `|d|₁·|e1|₁·|e2|₁` below which `det` is rounding noise.
const DET_NOISE: f32 = 8.0 / 16_777_216.0;

/// Tests every lane of `ray` against one triangle, two-sided.
#[cfg_attr(not(debug_assertions), inline(always))]
pub fn intersect<L: Lanes>(ray: &RayLanes<L>, tri: &PackedTriangle) -> LanesHit<L> {
    intersect_lanes::<L, false>(ray, &tri.splat())
}

/// Tests lane `i` of `ray` against lane `i` of `tri`; with `CULL`, back faces (`det ≤ 0`: the
/// normal `e1 × e2` points along the ray) are misses.
#[cfg_attr(not(debug_assertions), inline(always))]
pub fn intersect_lanes<L: Lanes, const CULL: bool>(
    ray: &RayLanes<L>,
    tri: &EdgeLanes<L>,
) -> LanesHit<L> {
    let zero = L::zero();
    let (v0, e1, e2, ng) = (tri.v0, tri.e1, tri.e2, tri.ng);

    // o + t·d = v0 + u·e1 + v·e2, i.e. [e1 e2 −d]·(u, v, t) = s with s = o − v0. Cramer's rule
    // with det = e1·(d × e2) = −d·Ng, Ng = e1 × e2 (stored), and r = s × d gives
    //   u = (r·e2)/det,  v = −(r·e1)/det,  t = (s·Ng)/det.
    // Ng is read from the layout (the same bits as computing it here at f32).
    let s = ray.origin - v0;
    let r = s.cross(ray.dir);
    let det = -ray.dir.dot(ng);
    let u_num = r.dot(e2);
    let v_num = -r.dot(e1);

    // Decide before dividing: flip the numerators by det's sign (exact) and compare them with
    // |det|, so 0 ≤ u, 0 ≤ v, u + v ≤ 1 need no division. Most tests of most packets end here,
    // before t is even formed.
    let abs_det = det.abs();
    let u_s = u_num.xor_sign(det);
    let v_s = v_num.xor_sign(det);
    let mut mask = ray.active
        & det.ne(zero)
        & abs_det.lt(L::splat(f32::INFINITY))
        & u_s.ge(zero)
        & v_s.ge(zero)
        & (u_s + v_s).le(abs_det);
    if CULL {
        mask = mask & det.gt(zero);
    }
    if mask.none() {
        return LanesHit::miss(mask);
    }
    // The plane distance, range-tested the same way (t_min ≤ t ≤ t_max scaled by |det|). In a
    // closest-hit query most tests that pass the edges end here: t_max is the nearest hit so far.
    let t_num = s.dot(ng);
    let t_s = t_num.xor_sign(det);
    mask = mask & t_s.ge(ray.t_min * abs_det) & t_s.le(ray.t_max * abs_det);
    if mask.none() {
        return LanesHit::miss(mask);
    }
    // det is rounding noise when it is below its own error bound, ≲ 3ε·|d|·|e1|·|e2| (L1 norms,
    // the cancellation in e1 × e2 included): a zero-area triangle (a needle whose packed edges
    // are parallel) or a ray within ~1e-6 rad of the plane. Such lanes are misses (found by the
    // fuzz harness: a "hit" 3e18 away from a degenerate 1e19 needle). Below the scalar's
    // normal range the products' rounding errors are absolute and this bound means nothing
    // (the BVH equality proptest, widened to scenes of 1e-13, found a "hit" at a vertex no box
    // test reaches): where `|e1|₁·|e2|₁` or `|d|₁·|e1|₁·|e2|₁` is below 2²⁶ times the smallest
    // normal value (2⁻¹⁰⁰ for f32), the lane is a miss; with `|d| = 1` that is the documented
    // underflow limit, triangles below ~1e-15. Tested last, all of it is computed only when some
    // lane would otherwise hit.
    let norm1 = |v: V3<L>| v.x.abs() + v.y.abs() + v.z.abs();
    let edges = norm1(e1) * norm1(e2);
    let floor = L::splat_scalar(L::Scalar::from_f64(L::Scalar::MIN_NORMAL * 67_108_864.0));
    let det_noise = L::splat(DET_NOISE) * norm1(ray.dir) * edges;
    mask =
        mask & abs_det.gt(det_noise) & edges.ge(floor) & det_noise.ge(floor * L::splat(DET_NOISE));
    if mask.none() {
        return LanesHit::miss(mask);
    }

    // Divide only when some lane is kept, and only t: the barycentrics stay numerators over det
    // until a query has picked its closest hit. The scaled range test above rounds t_max·|det|,
    // so the authoritative range and finiteness check is made on the divided t.
    // `+ 0` maps −0 to +0 (and nothing else): one canonical zero for every query.
    let t = t_num / det + zero;
    mask = mask & t_in_range(ray, t);
    // On grazing rays t can lie outside the triangle's box (its error grows as 1/|cos θ|):
    // raised to the box's entry, and a miss where the ray leaves the box before t_min, so no
    // tree's box test culls a reported hit (`within_box`). The vertices relative to the origin:
    // v0 − o, then v1 − o and v2 − o as the kernel's algebra has them, (v0 − o) + e.
    let a = v0 - ray.origin;
    let (t, mask) = within_box::<L, true, 3>(ray, mask, t, [a, a + e1, a + e2]);
    LanesHit {
        mask,
        t,
        u: u_num,
        v: v_num,
        scale: det,
    }
}

/// Former name of [`intersect_lanes`].
#[deprecated(
    since = "0.1.0",
    note = "renamed `intersect_lanes`: it tests one triangle per lane"
)]
#[cfg_attr(not(debug_assertions), inline(always))]
pub fn intersect_with<L: Lanes, const CULL: bool>(
    ray: &RayLanes<L>,
    tri: &EdgeLanes<L>,
) -> LanesHit<L> {
    intersect_lanes::<L, CULL>(ray, tri)
}
