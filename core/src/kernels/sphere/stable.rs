//! Numerically sound ray-sphere (Ray Tracing Gems ch. 7): one generic body for every lane width;
//! `L = f32` is the scalar twin.
//!
//! # Guarantees (standard tier)
//! - **Same bits** across `f32`, `f32x4`, `f32x8`, `f32x16` and across builds (proptested).
//! - The discriminant is formed from the perpendicular distance of the centre to the ray line:
//!   `√(Δ/4) = √a·√(r² − |l|²)`, `l = f − (f·d/a) d`, not `b² − 4ac`, so small distant spheres
//!   keep their hit/miss answer, and no product underflows the sign of `r² − |l|²`; the roots come
//!   from `q = −(h + sign(h)·√(Δ/4))` as `t = c/q` and `t = q/a`, so neither root cancels.
//! - The nearest root in `[t_min, t_max]` is the hit; an origin inside gets the far root. A root
//!   before the ray's entry into the sphere's bounding box (near tangency, where the bound below
//!   grows) is raised to that entry, which only moves it toward the exact root, and a ray that
//!   leaves that box before `t_min` is a miss: no BVH box that holds the sphere is entered after
//!   a reported hit on it or left before `t_min`.
//! - **t error bound:** `|t − t_exact| ≤ 8·ε·max(|t|, (|f| + r)/|d|)/√(Δ/(a r²))` (the last factor
//!   is the roots' sensitivity near tangency). Hit/miss is exact whenever
//!   `|Δ/(a r²)| > 64·ε·(1 + |f|/r)`.
//! - Reported hits always have finite `t ∈ [t_min, t_max]`.
//!
//! # Limits
//! - `c = f·f − r²` still cancels for an origin next to the surface of a huge sphere: there `t`
//!   near 0 has large relative error.
//! - The packed sphere stores r² in f32: for huge radii that rounding moves the surface (by
//!   0.002 for r = 1e6), for every tier including f64.
//! - **Range:** directions with `d·d` a normal f32 whose reciprocal is normal too (`|d|` in about
//!   `[1.1e-19, 9.2e18]`); outside it every test is a miss. Where `h = f·d`, `c` or `q` overflows
//!   (`|f|·|d|` or `|f|²` near `f32::MAX`: unnormalised directions in scenes beyond ~1e19) the test
//!   is a miss, never a false hit (the f64 tier covers that range).
//! - **Misses by construction:** a squared radius that is not a finite normal f32 `> 0` (what
//!   [`PackedSphere::new`] stores as NaN, but also a hand-packed ±0, subnormal, negative or
//!   infinite one: a sphere the BVH leaves out too), zero or non-finite directions and
//!   non-finite inputs.
//!
//! # Measured
//! The `t` error at most `4.0·ε·max(|t|, (|f| + r)/|d|)/√(Δ/(a r²))` over near, distant
//! (1e2…1e4 r) and tiny cases (radii down to [`PackedSphere::MIN_RADIUS`], `|d|` down to 1.2e-19); the naive form
//! gets 48 % of answers wrong outside the hit/miss margin at 1e4 r.

use crate::hit::{nearest_root_in_range, LanesHit};
use crate::lanes::{LaneMask, Lanes, Scalar};
use crate::prim::{PackedSphere, RayLanes};
use crate::prim::{Primitive, SphereLanes};

/// Per-ray precomputation: `a = d·d`, `√a` and `1/a`, correctly rounded (a division and a square
/// root per ray, not per test). `a` is NaN (every test a miss) where it is not normal or its
/// reciprocal would not be: `|d|` outside about `[1.1e-19, 9.2e18]` for f32.
#[derive(Clone, Copy, Debug)]
pub struct SphereRay<L> {
    a: L,
    sqrt_a: L,
    inv_a: L,
}

impl<L: Lanes> SphereRay<L> {
    /// Precomputes `ray`'s `a = d·d`, `√a` and `1/a`.
    #[cfg_attr(not(debug_assertions), inline(always))]
    pub fn new(ray: &RayLanes<L>) -> Self {
        let a = ray.dir.dot(ray.dir);
        let min = L::splat_scalar(L::Scalar::from_f64(L::Scalar::MIN_NORMAL));
        let max = L::splat_scalar(L::Scalar::from_f64(1.0 / L::Scalar::MIN_NORMAL));
        let a = L::select(a.ge(min) & a.le(max), a, L::splat(f32::NAN));
        Self {
            a,
            sqrt_a: a.sqrt(),
            inv_a: L::splat(1.0) / a,
        }
    }
}

/// Tests every lane of `ray` against one sphere.
#[cfg_attr(not(debug_assertions), inline(always))]
pub fn intersect<L: Lanes>(ray: &RayLanes<L>, sphere: &PackedSphere) -> LanesHit<L> {
    intersect_lanes(ray, &SphereRay::new(ray), &sphere.splat())
}

/// Tests lane `i` of `ray` (precomputed in `pre`) against lane `i` of `sphere`.
#[cfg_attr(not(debug_assertions), inline(always))]
pub fn intersect_lanes<L: Lanes>(
    ray: &RayLanes<L>,
    pre: &SphereRay<L>,
    sphere: &SphereLanes<L>,
) -> LanesHit<L> {
    let zero = L::zero();
    let d = ray.dir;
    let r2 = sphere.radius_sq;
    // |f + t·d|² = r² with f = o − c: a t² + 2h t + c = 0, a = d·d, h = f·d, c = f·f − r².
    let f = ray.origin - sphere.center;
    let (a, inv_a) = (pre.a, pre.inv_a);
    let h = f.dot(d);
    let c = f.dot(f) - r2;
    // Δ/4 = h² − a c = a (r² − |l|²), where l = f − (h/a) d is the centre's perpendicular offset
    // from the ray line: no cancellation between two large nearly equal terms. h/a is formed as
    // h·(1/a) (two roundings, not one): a division on every test's critical path cost more than
    // the rest of the test.
    // √(Δ/4) = √a·√(r² − |l|²): the sign is that of r² − |l|², which no product can flush to
    // −0, and the root keeps its range where a·(r² − |l|²) would underflow (|d|·r ≲ 1e-19).
    let l = f - d * (h * inv_a);
    let w = r2 - l.dot(l);
    let mask = ray.active & a.gt(zero) & r2.ge(L::splat(f32::MIN_POSITIVE)) & w.ge(zero);
    if mask.none() {
        return LanesHit::miss(mask);
    }

    // Stable roots: q = −(h + sign(h)·√(Δ/4)) adds like signs; then t = c/q and t = q/a.
    let sq = pre.sqrt_a * w.sqrt();
    let q = -(h + L::select(h.lt(zero), -sq, sq));
    // Where q overflowed (|h| near f32::MAX), the roots are meaningless: c/q would give a false
    // hit at t = 0. A miss instead.
    let mask = mask & q.is_finite();
    let t0 = c / q;
    let t1 = q * inv_a;
    let ordered = t0.le(t1);
    let near = L::select(ordered, t0, t1);
    let far = L::select(ordered, t1, t0);
    nearest_root_in_range(ray, mask, (near, far), f, r2)
}
