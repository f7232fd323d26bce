//! The conservative ray-box (slab) test: one generic body, for one ray against the eight
//! children of a node (`f32x8`, the boxes in lanes) and for a packet against one box (the rays
//! in lanes).
//!
//! # Contract
//! The test never rejects a box that the ray meets within `[t_min, t_max]` — with the box grown
//! by the build slack and the ray's origin slack ([`SLACK`]) — for any finite ray, including
//! directions with zero or −0 components, subnormal components, and origins inside or on the box.
//!
//! Derivation (pbrt-v4 `Bounds3::IntersectP`; Ize 2013, "Robust BVH Ray Traversal"): the slab of
//! axis `k` is crossed at `t = (b − o)·(1/d)`, with `1/d` correctly rounded (no `recip`
//! estimate), the subtraction and the product each rounded once: three roundings, so the computed
//! `t` is within `γ₃·|t|` of the exact one (plus 2⁻¹⁵⁰ absolute where it is subnormal). The near
//! distance is therefore moved down and the far one up by `2γ₃` of themselves plus 2⁻¹²⁶ before
//! they are compared. `o/d` is never precomputed (that form
//! cancels and has no such bound), and nothing is fused.
//!
//! Infinite reciprocals (zero or −0 components) give `±inf` slab distances with the right sign;
//! where `b − o` is also 0 the product is NaN, meaning the ray runs inside that face's plane: that
//! axis then does not bound the ray (tested for +0 and −0 on both faces). A subnormal
//! component whose reciprocal overflows is treated the same way: that axis does not bound the
//! ray. The test is then only looser, never wrong.

use crate::lanes::V3;
use crate::lanes::{LaneMask, Lanes};
use crate::prim::RayLanes;

/// Relative slack of boxes and origins: 2⁻¹⁷ (≈ 128 ulp of f32) of the largest coordinate
/// magnitude. It covers every tier's hit/miss margin (≤ 64·ε of the distance from the origin to
/// the primitive's vertices, measured in the accuracy report), so no kernel hit lies outside a
/// box the traversal visits.
pub const SLACK: f32 = 1.0 / 131_072.0;

/// `2γ₃` for f32 (`γₙ = nε/(1 − nε)`, ε = 2⁻²⁴), rounded up.
const TWO_GAMMA3: f32 = 3.6e-7;

/// A ray (per lane) prepared for box tests: the origin moved by its slack both ways, and the
/// correctly rounded reciprocal direction.
#[derive(Clone, Copy, Debug)]
pub struct BoxRay<L: Lanes> {
    /// `o + δ`, for the lower planes.
    pub o_plus: V3<L>,
    /// `o − δ`, for the upper planes.
    pub o_minus: V3<L>,
    /// `1/d` (±inf for ±0; NaN where `d` is subnormal and `1/d` overflows).
    pub inv: V3<L>,
    /// `t_min` per lane.
    pub t_min: L,
    /// Lanes with a finite origin and direction and a non-zero direction: the only ones any
    /// kernel can report a hit for.
    pub valid: L::Mask,
    /// Some lane has a zero or subnormal direction component (an infinite or NaN reciprocal):
    /// only then can a slab distance be NaN, and [`slab`] takes its NaN-aware form.
    pub open_axes: bool,
}

impl<L: Lanes> BoxRay<L> {
    /// Prepares every lane of `ray`.
    #[inline(always)]
    pub fn new(ray: &RayLanes<L>) -> Self {
        let (o, d) = (ray.origin, ray.dir);
        let zero = L::zero();
        let m = max3(o.x.abs(), o.y.abs(), o.z.abs());
        let delta = m * L::splat(SLACK);
        let one = L::splat(1.0);
        let nan = L::splat(f32::NAN);
        let inv1 = |x: L| {
            let r = one / x;
            L::select(x.ne(zero) & !r.is_finite(), nan, r)
        };
        let finite = o.x.is_finite()
            & o.y.is_finite()
            & o.z.is_finite()
            & d.x.is_finite()
            & d.y.is_finite()
            & d.z.is_finite();
        let nonzero = d.x.ne(zero) | d.y.ne(zero) | d.z.ne(zero);
        let inv = V3::new(inv1(d.x), inv1(d.y), inv1(d.z));
        let open = !(inv.x.is_finite() & inv.y.is_finite() & inv.z.is_finite());
        Self {
            o_plus: V3::new(o.x + delta, o.y + delta, o.z + delta),
            o_minus: V3::new(o.x - delta, o.y - delta, o.z - delta),
            inv,
            t_min: ray.t_min,
            valid: ray.active & finite & nonzero,
            open_axes: open.any(),
        }
    }
}

#[inline(always)]
fn max3<L: Lanes>(a: L, b: L, c: L) -> L {
    let m = L::select(a.ge(b), a, b);
    L::select(m.ge(c), m, c)
}

/// Per lane: does the ray meet the box `[lo, hi]` within `[t_min, t_max]`? Returns the mask
/// (`valid` lanes only) and the conservative entry distance (meaningful where the mask is set).
#[inline(always)]
pub fn slab<L: Lanes>(lo: V3<L>, hi: V3<L>, r: &BoxRay<L>, t_max: L) -> (L::Mask, L) {
    let mut near = r.t_min;
    let mut far = t_max;
    let nan = L::splat(f32::NAN);
    let open_axes = r.open_axes;
    let mut axis = |lo: L, hi: L, op: L, om: L, inv: L| {
        let t0 = (lo - op) * inv;
        let t1 = (hi - om) * inv;
        if !open_axes {
            // Every reciprocal is finite and non-zero: no NaN can arise.
            near = t1.min_or_rhs(t0).max_or_rhs(near);
            far = t0.max_or_rhs(t1).min_or_rhs(far);
            return;
        }
        // t0 + t1 is NaN exactly when one of them is (0·inf: the ray runs in this face's plane)
        // or they are opposite infinities (d = 0 with the origin inside the slab): in both cases
        // the axis does not bound the ray, so near and far become NaN, which the reduction skips
        // (`a.max_or_rhs(b)` is `b` when either is NaN).
        let open = (t0 + t1).ne(t0 + t1);
        let n = L::select(open, nan, t1.min_or_rhs(t0));
        let f = L::select(open, nan, t0.max_or_rhs(t1));
        near = n.max_or_rhs(near);
        far = f.min_or_rhs(far);
    };
    axis(lo.x, hi.x, r.o_plus.x, r.o_minus.x, r.inv.x);
    axis(lo.y, hi.y, r.o_plus.y, r.o_minus.y, r.inv.y);
    axis(lo.z, hi.z, r.o_plus.z, r.o_minus.z, r.inv.z);
    // Relative widening by 2γ₃, plus an absolute 2⁻¹²⁶ for distances in the subnormal range
    // (huge directions), where a rounding is off by up to 2⁻¹⁵⁰ whatever the value.
    let c = L::splat(TWO_GAMMA3);
    let tiny = L::splat(f32::MIN_POSITIVE);
    let near = near - (near.abs() * c + tiny);
    let far = far + (far.abs() * c + tiny);
    (r.valid & near.le(far), near)
}

/// The box slack of a box at build time: `lo`, `hi` moved outward by [`SLACK`] of the box's
/// largest coordinate magnitude, then by one ulp.
pub fn widen(lo: [f32; 3], hi: [f32; 3]) -> ([f32; 3], [f32; 3]) {
    let m = (0..3).fold(0.0f32, |m, k| m.max(lo[k].abs()).max(hi[k].abs()));
    let delta = m * SLACK;
    (
        core::array::from_fn(|k| (lo[k] - delta).next_down()),
        core::array::from_fn(|k| (hi[k] + delta).next_up()),
    )
}

/// `t` moved up so that a kernel hit at exactly `t` passes the kernels' scaled range test: the
/// traversal's `t_max` once it has a hit at `t` (the final choice compares exactly).
#[inline(always)]
#[cfg(feature = "wide")]
pub(crate) fn loosen<S: crate::lanes::Scalar>(t: S) -> S {
    let x = t.to_f64();
    S::from_f64(x + x.abs() * (1.0 / 1_048_576.0) + f64::from(f32::MIN_POSITIVE))
}
